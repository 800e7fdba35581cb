"""simbot serve: a course's competition over HTTP (DESIGN.md, "The
competition over the internet").

Teams, each with one token (stored hashed), submit Dynamic C programs; a
submission is compiled at once by the simbot executable and kept, frozen,
as the team's next version. The instructor's token (written once to
DATA/instructor-token, mode 0600) creates teams. Storage is SQLAlchemy
(SQLite by default, PostgreSQL by URL) with Alembic migrations; no text a
user sends ever becomes a file path.

Modules: models (the tables), db (engine, sessions, migrations), tokens
(creating, hashing and comparing tokens), compile (a submission through
`simbot compile`), app (the FastAPI application), __main__ (the command
line `simbot serve` runs).
"""
