"""The lab graded: its problems and their settings, the checks that decide each verdict, the editions, and
the assignment configuration that chooses among them (`assignment.toml`, documented in ASSIGNMENT.md)."""
