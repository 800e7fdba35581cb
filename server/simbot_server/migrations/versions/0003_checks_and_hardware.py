"""Each submission's course checks, kept to be shown with it; a team's
robot (a hardware file made by its /teams/ID/robot form) and the hardware
each match's robots played with, kept with the match so that it is
replayed as it was played; whether a round robin uses the teams' robots.

Revision ID: 0003
Revises: 0002
"""
import sqlalchemy as sa
from alembic import op

revision = "0003"
down_revision = "0002"
branch_labels = None
depends_on = None


def upgrade():
    op.add_column("submissions", sa.Column("checks", sa.Text))
    op.add_column("teams", sa.Column("hardware", sa.Text))
    op.add_column("matches", sa.Column("a_hardware", sa.Text))
    op.add_column("matches", sa.Column("b_hardware", sa.Text))
    op.add_column("tournaments", sa.Column("team_hardware", sa.Integer, nullable=False,
                                           server_default="0"))
