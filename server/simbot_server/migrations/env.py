"""Alembic's environment: migrations run on the connection db.migrate
hands over (no alembic.ini; the server never builds a URL from text)."""
from alembic import context

from simbot_server.models import Base

connection = context.config.attributes["connection"]
context.configure(connection=connection, target_metadata=Base.metadata,
                  render_as_batch=connection.dialect.name == "sqlite")
with context.begin_transaction():
    context.run_migrations()
