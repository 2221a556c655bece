"""One grading, top-down: `grade` -> `plan` -> `session` (pytest-xdist) -> `plugin` -> `cases` ->
`execution` (the sandbox) -> `outcomes` (reports as they finish); `batch` grades many files in one run."""
