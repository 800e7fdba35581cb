"""The database's tables (SQLAlchemy declarative). The schema itself is
made by the Alembic migrations in migrations/versions/, which must stay in
step with these classes (the server's test compares them)."""
from sqlalchemy import BigInteger, Column, DateTime, ForeignKey, Integer, String, Text, UniqueConstraint, func
from sqlalchemy.orm import declarative_base, relationship

Base = declarative_base()

# Limits beside what they limit (bytes or characters).
MAX_TEAM_NAME = 64
MAX_PROGRAM_BYTES = 64 * 1024
MAX_FILE_NAME = 128
MAX_ID = 2**63 - 1  # a row id: SQLite's INTEGER is 64-bit, and a larger int overflows its driver


class Setting(Base):
    """Server-wide values: the instructor token's hash."""
    __tablename__ = "settings"
    key = Column(String(64), primary_key=True)
    value = Column(String(256), nullable=False)


class Team(Base):
    __tablename__ = "teams"
    id = Column(Integer, primary_key=True)
    name = Column(String(MAX_TEAM_NAME), nullable=False, unique=True)
    token_hash = Column(String(64), nullable=False, unique=True)
    # The team's robot: a hardware file (TOML) from its /teams/ID/robot form,
    # checked by simbot's loader; None: the course's profile as it is.
    hardware = Column(Text)
    created = Column(DateTime, nullable=False, server_default=func.now())
    submissions = relationship("Submission", back_populates="team", order_by="Submission.version")


class Submission(Base):
    """A frozen version of a team's program: never changed once made."""
    __tablename__ = "submissions"
    __table_args__ = (UniqueConstraint("team_id", "version"),)
    id = Column(Integer, primary_key=True)
    team_id = Column(Integer, ForeignKey("teams.id"), nullable=False)
    version = Column(Integer, nullable=False)
    file_name = Column(String(MAX_FILE_NAME), nullable=False)  # as the team named it: shown, never a path
    source = Column(Text, nullable=False)
    warnings = Column(Text, nullable=False)  # the compiler's warning lines, one per line
    checks = Column(Text)  # the course's checks on it: simbot check's cases (JSON), None if none
    created = Column(DateTime, nullable=False, server_default=func.now())
    team = relationship("Team", back_populates="submissions")


class Tournament(Base):
    """The instructor's round robin: every team's latest version at its
    creation plays every other `rounds` times, under `rules`; the order of
    the games (the brackets) is shuffled by `seed`, recorded here."""
    __tablename__ = "tournaments"
    id = Column(Integer, primary_key=True)
    rules = Column(String(64))
    seconds = Column(Integer, nullable=False)
    rounds = Column(Integer, nullable=False)
    reload_on_fault = Column(Integer, nullable=False)  # 0 or 1
    seed = Column(BigInteger, nullable=False)
    team_hardware = Column(Integer, nullable=False, server_default="0")  # 1: each team's robot
    created = Column(DateTime, nullable=False, server_default=func.now())


class Match(Base):
    """A match in the queue, running, or done: robot A is a submission,
    robot B a submission or a house robot (a shipped program by name).
    `result` is simbot match's JSON; `error` why it failed."""
    __tablename__ = "matches"
    id = Column(Integer, primary_key=True)
    kind = Column(String(16), nullable=False)  # "scrimmage" or "tournament"
    tournament_id = Column(Integer, ForeignKey("tournaments.id"))
    rules = Column(String(64))
    reload_on_fault = Column(Integer, nullable=False, default=0, server_default="0")
    a_submission_id = Column(Integer, ForeignKey("submissions.id"), nullable=False)
    b_submission_id = Column(Integer, ForeignKey("submissions.id"))
    b_house = Column(String(64))
    # The hardware files the robots played with (copied from the teams' at
    # queueing, so the match can be played again as it was); None: none.
    a_hardware = Column(Text)
    b_hardware = Column(Text)
    seed = Column(BigInteger, nullable=False)
    seconds = Column(Integer, nullable=False)
    status = Column(String(16), nullable=False, index=True)  # queued, running, done, failed
    result = Column(Text)
    error = Column(Text)
    created = Column(DateTime, nullable=False, server_default=func.now())
