"""The database: an engine for a URL (SQLite file under the data folder by
default, PostgreSQL by URL), its schema brought to the newest Alembic
revision at start, and sessions."""
import os

from alembic import command
from alembic.config import Config
from sqlalchemy import create_engine, event
from sqlalchemy.orm import sessionmaker

MIGRATIONS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "migrations")


def default_url(data_dir):
    return "sqlite:///" + os.path.join(os.path.abspath(data_dir), "simbot.sqlite3")


def make_engine(url):
    if url.startswith("sqlite"):
        engine = create_engine(url, connect_args={"check_same_thread": False})

        # SQLite checks foreign keys only when asked, per connection.
        @event.listens_for(engine, "connect")
        def _foreign_keys(connection, _record):
            connection.execute("PRAGMA foreign_keys=ON")

        return engine
    engine = create_engine(url, pool_pre_ping=True)
    if engine.dialect.name == "postgresql":
        # The tables' times (server_default now()) are UTC, as SQLite's
        # CURRENT_TIMESTAMP is: PostgreSQL gives a timestamp without a zone
        # in the session's time zone, which is the database's or the
        # server's setting unless set here.
        @event.listens_for(engine, "connect")
        def _utc(connection, _record):
            cursor = connection.cursor()
            cursor.execute("SET TIME ZONE 'UTC'")
            cursor.close()
            connection.commit()

    return engine


def migrate(engine):
    """Upgrades the schema to the newest revision (a no-op when it is)."""
    config = Config()
    config.set_main_option("script_location", MIGRATIONS)
    with engine.begin() as connection:
        config.attributes["connection"] = connection
        command.upgrade(config, "head")


def sessions(engine):
    return sessionmaker(bind=engine, expire_on_commit=False)
