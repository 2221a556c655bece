"""Courses, assignments, staff and extensions; every student row becomes an enrolment of a course, and every
submission, override and LTI link belongs to an assignment.

What a database of before courses holds moves, with nothing lost, into the embedded default: course 1
(``default``) and its assignment 1 (``default``), whose lab, edition, seeds, due date and policies the
service writes from its settings at every start (``api.courses.sync_default``). An LTI user's student row
becomes that user's enrolment in the default course (``students.lti_user_id``); links stay keyed by
platform and link id, now with the deployment too.
"""

from __future__ import annotations

from datetime import UTC, datetime

import sqlalchemy as sa
from alembic import op

revision = "0004"
down_revision = "0003"
branch_labels = None
depends_on = None

DEFAULT_COURSE_ID = 1
DEFAULT_ASSIGNMENT_ID = 1
SQLITE_NAMES = {"uq": "uq_%(table_name)s_%(column_0_name)s", "fk": "fk_%(table_name)s_%(column_0_name)s"}
"""Names for SQLite's reflected unnamed constraints, so that batch mode can drop them by name."""


def upgrade() -> None:
    bind = op.get_bind()
    sqlite = bind.dialect.name == "sqlite"  # batch mode recreates tables: api.database lifts the keys
    _create_tables()
    _insert_default(bind)
    _students(bind, sqlite)
    for table in ("submissions", "overrides", "lti_links"):
        _belong_to_the_default_assignment(table)
    with op.batch_alter_table("lti_sessions") as batch:
        batch.add_column(sa.Column("course_id", sa.Integer(), nullable=True))
        batch.create_foreign_key("fk_lti_sessions_course_id", "courses", ["course_id"], ["id"])
    with op.batch_alter_table("lti_links") as batch:
        batch.drop_constraint("uq_lti_links_platform_link", type_="unique")
        batch.create_unique_constraint(
            "uq_lti_links_platform_deployment_link", ["platform_id", "deployment_id", "resource_link_id"]
        )


def _create_tables() -> None:
    op.create_table(
        "courses",
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("slug", sa.String(64), nullable=False, unique=True),
        sa.Column("title", sa.String(200), nullable=False),
        sa.Column("lti_platform_id", sa.Integer(), sa.ForeignKey("lti_platforms.id"), nullable=True),
        sa.Column("lti_deployment_id", sa.String(255), nullable=True),
        sa.Column("lti_context_id", sa.String(255), nullable=True),
        sa.Column("created_at", sa.DateTime(), nullable=False),
        sa.UniqueConstraint(
            "lti_platform_id", "lti_deployment_id", "lti_context_id", name="uq_courses_lti_context"
        ),
    )
    op.create_table(
        "assignments",
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("course_id", sa.Integer(), sa.ForeignKey("courses.id"), nullable=False),
        sa.Column("slug", sa.String(64), nullable=False),
        sa.Column("title", sa.String(200), nullable=False),
        sa.Column("lab", sa.String(32), nullable=True),
        sa.Column("edition", sa.String(32), nullable=True),
        sa.Column("config_toml", sa.Text(), nullable=True),
        sa.Column("seed_policy", sa.String(16), nullable=False),
        sa.Column("seed", sa.Integer(), nullable=False),
        sa.Column("release_seeds", sa.Boolean(), nullable=False),
        sa.Column("due_date", sa.DateTime(), nullable=True),
        sa.Column("gradebook_policy", sa.String(16), nullable=False),
        sa.Column("late_policy", sa.JSON(), nullable=True),
        sa.Column("created_at", sa.DateTime(), nullable=False),
        sa.UniqueConstraint("course_id", "slug", name="uq_assignments_course_slug"),
    )
    op.create_index("ix_assignments_course_id", "assignments", ["course_id"])
    op.create_table(
        "staff",
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("course_id", sa.Integer(), sa.ForeignKey("courses.id"), nullable=False),
        sa.Column("role", sa.String(16), nullable=False),
        sa.Column("name", sa.String(100), nullable=False),
        sa.Column("token_sha256", sa.String(64), nullable=True, unique=True),
        sa.Column("lti_user_id", sa.Integer(), sa.ForeignKey("lti_users.id"), nullable=True),
        sa.Column("created_at", sa.DateTime(), nullable=False),
        sa.UniqueConstraint("course_id", "lti_user_id", name="uq_staff_course_lti_user"),
    )
    op.create_index("ix_staff_course_id", "staff", ["course_id"])
    op.create_table(
        "extensions",
        sa.Column("id", sa.Integer(), primary_key=True),
        sa.Column("assignment_id", sa.Integer(), sa.ForeignKey("assignments.id"), nullable=False),
        sa.Column("student_id", sa.Integer(), sa.ForeignKey("students.id"), nullable=False),
        sa.Column("due", sa.DateTime(), nullable=False),
        sa.Column("reason", sa.Text(), nullable=False),
        sa.Column("author", sa.String(100), nullable=False),
        sa.Column("created_at", sa.DateTime(), nullable=False),
        sa.UniqueConstraint("assignment_id", "student_id", name="uq_extensions_assignment_student"),
    )


def _insert_default(bind: sa.Connection) -> None:
    now = datetime.now(UTC).replace(tzinfo=None)
    courses = sa.table(
        "courses", sa.column("id"), sa.column("slug"), sa.column("title"), sa.column("created_at")
    )
    op.bulk_insert(
        courses, [{"id": DEFAULT_COURSE_ID, "slug": "default", "title": "The course", "created_at": now}]
    )
    assignments = sa.table(
        "assignments",
        *(
            sa.column(name)
            for name in (
                "id",
                "course_id",
                "slug",
                "title",
                "seed_policy",
                "seed",
                "release_seeds",
                "gradebook_policy",
                "created_at",
            )
        ),
    )
    op.bulk_insert(
        assignments,
        [
            {
                "id": DEFAULT_ASSIGNMENT_ID,
                "course_id": DEFAULT_COURSE_ID,
                "slug": "default",
                "title": "The assignment",
                "seed_policy": "random",
                "seed": 0,
                "release_seeds": False,
                "gradebook_policy": "latest",
                "created_at": now,
            }
        ],
    )
    if bind.dialect.name == "postgresql":  # explicit ids leave the sequences behind
        for table in ("courses", "assignments"):
            op.execute(
                f"SELECT setval(pg_get_serial_sequence('{table}', 'id'), (SELECT max(id) FROM {table}))"
            )


def _students(bind: sa.Connection, sqlite: bool) -> None:
    with op.batch_alter_table("students") as batch:
        batch.add_column(sa.Column("course_id", sa.Integer(), nullable=True))
        batch.add_column(sa.Column("lti_user_id", sa.Integer(), nullable=True))
    op.execute(f"UPDATE students SET course_id = {DEFAULT_COURSE_ID}")
    learner = "SELECT lti_users.id FROM lti_users WHERE lti_users.student_id = students.id"
    op.execute(f"UPDATE students SET lti_user_id = ({learner})")
    with op.batch_alter_table("lti_users", naming_convention=SQLITE_NAMES if sqlite else None) as batch:
        if sqlite:
            batch.drop_constraint("uq_lti_users_student_id", type_="unique")
            batch.drop_constraint("fk_lti_users_student_id", type_="foreignkey")
        batch.drop_column("student_id")
    with op.batch_alter_table("students", naming_convention=SQLITE_NAMES if sqlite else None) as batch:
        batch.alter_column("course_id", existing_type=sa.Integer(), nullable=False)
        batch.drop_constraint("uq_students_name" if sqlite else "students_name_key", type_="unique")
        batch.create_unique_constraint("uq_students_course_name", ["course_id", "name"])
        batch.create_unique_constraint("uq_students_course_lti_user", ["course_id", "lti_user_id"])
        batch.create_foreign_key("fk_students_course_id", "courses", ["course_id"], ["id"])
        batch.create_foreign_key("fk_students_lti_user_id", "lti_users", ["lti_user_id"], ["id"])
        batch.create_index("ix_students_course_id", ["course_id"])


def _belong_to_the_default_assignment(table: str) -> None:
    with op.batch_alter_table(table) as batch:
        batch.add_column(sa.Column("assignment_id", sa.Integer(), nullable=True))
    op.execute(f"UPDATE {table} SET assignment_id = {DEFAULT_ASSIGNMENT_ID}")
    with op.batch_alter_table(table) as batch:
        batch.alter_column("assignment_id", existing_type=sa.Integer(), nullable=False)
        batch.create_foreign_key(f"fk_{table}_assignment_id", "assignments", ["assignment_id"], ["id"])
        batch.create_index(f"ix_{table}_assignment_id", ["assignment_id"])


def downgrade() -> None:
    raise NotImplementedError(
        "0004 (courses) is not reversible: a database with several courses has no single-class form; "
        "restore the backup taken before upgrading"
    )
