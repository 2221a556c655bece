"""LTI hardened: tokens spent once (registration tickets, lab picker forms), the origins that may frame
the tool, per platform, and sessions bound to a browser's cookie."""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0005"
down_revision = "0004"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "lti_spent_tokens",
        sa.Column("jti", sa.String(100), primary_key=True),
        sa.Column("purpose", sa.String(32), nullable=False),
        sa.Column("expires_at", sa.DateTime(), nullable=False, index=True),
    )
    with op.batch_alter_table("lti_platforms") as batch:
        batch.add_column(sa.Column("frame_ancestors", sa.JSON(), nullable=False, server_default="[]"))
    with op.batch_alter_table("lti_sessions") as batch:
        batch.add_column(sa.Column("browser_sha256", sa.String(64), nullable=True))


def downgrade() -> None:
    with op.batch_alter_table("lti_sessions") as batch:
        batch.drop_column("browser_sha256")
    with op.batch_alter_table("lti_platforms") as batch:
        batch.drop_column("frame_ancestors")
    op.drop_table("lti_spent_tokens")
