"""The child harness run inside the sandbox: imports only the stdlib, numpy, gymnasium and grader.compat."""
