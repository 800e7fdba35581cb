"""The match queue (scrimmages and tournament games) and tournaments.

Revision ID: 0002
Revises: 0001
"""
import sqlalchemy as sa
from alembic import op

revision = "0002"
down_revision = "0001"
branch_labels = None
depends_on = None


def upgrade():
    op.create_table(
        "tournaments",
        sa.Column("id", sa.Integer, primary_key=True),
        sa.Column("rules", sa.String(64)),
        sa.Column("seconds", sa.Integer, nullable=False),
        sa.Column("rounds", sa.Integer, nullable=False),
        sa.Column("reload_on_fault", sa.Integer, nullable=False),
        sa.Column("seed", sa.BigInteger, nullable=False),
        sa.Column("created", sa.DateTime, nullable=False, server_default=sa.func.now()),
    )
    op.create_table(
        "matches",
        sa.Column("id", sa.Integer, primary_key=True),
        sa.Column("kind", sa.String(16), nullable=False),
        sa.Column("tournament_id", sa.Integer, sa.ForeignKey("tournaments.id")),
        sa.Column("rules", sa.String(64)),
        sa.Column("reload_on_fault", sa.Integer, nullable=False, server_default="0"),
        sa.Column("a_submission_id", sa.Integer, sa.ForeignKey("submissions.id"), nullable=False),
        sa.Column("b_submission_id", sa.Integer, sa.ForeignKey("submissions.id")),
        sa.Column("b_house", sa.String(64)),
        sa.Column("seed", sa.BigInteger, nullable=False),
        sa.Column("seconds", sa.Integer, nullable=False),
        sa.Column("status", sa.String(16), nullable=False),
        sa.Column("result", sa.Text),
        sa.Column("error", sa.Text),
        sa.Column("created", sa.DateTime, nullable=False, server_default=sa.func.now()),
    )
    op.create_index("ix_matches_status", "matches", ["status"])


def downgrade():
    op.drop_index("ix_matches_status", "matches")
    op.drop_table("matches")
    op.drop_table("tournaments")
