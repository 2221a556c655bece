"""Grading jobs: the queue protocol, its backends, and the worker pool that runs gradings.

In detail:

The submission row is the job and the only truth. `job_queue.py`: `JobQueue` (conditional UPDATEs with a
lease: `claim(worker_id, submission_id=None)`, `renew`, `add_progress`, `complete`, `fail`, `retry`,
`release`; every change is refused once the worker lost the lease) and `Dispatcher` (`submitted(id)`,
`close()`). `runner.run_job` grades one claimed job in a niced child process (`child.py`) whatever the
backend.

- Embedded (default): `local.DatabaseQueue` + `local.PollingDispatcher` (does nothing); `pool.WorkerPool`
  threads poll the rows, in `gymgrade serve` or `gymgrade worker`.
- Distributed (`GYMGRADE_BROKER_URL=redis://...`): `distributed.py` makes the Celery app (Redis broker, no
  result backend; `acks_late`, prefetch 1, visibility timeout > grading timeout) and `CeleryDispatcher`,
  which sends task `gymgrade.grade_submission(id)` from a background thread (an upload never waits for
  Redis) and keeps a marker `gymgrade:task:<id>` = the row's attempts when sent. `celery_worker.py`: the
  worker (`gymgrade worker`; thread pool, the CPU work is in the grading child) claims the row named by the
  task with the same conditional UPDATE (finished, failed or held under a live lease: the task does
  nothing), runs `run_job`, and re-enqueues a row that went back to the queue. `reconciler.py` (in the
  server, at start-up and every `GYMGRADE_RECONCILE_SECONDS`): every queued row, and every running row
  whose lease expired, whose marker does not hold its current attempts gets a new task. So a SIGKILLed
  worker's job is re-run after at most lease + reconcile period; a Redis restart or flush loses no job;
  duplicates are no-ops. When Celery's own loop ends on an error it does not recover from (kombu failing
  inside its reconnection after a broker restart), `run_worker` replaces the process with a fresh run of
  the same command (`os.execve`, same pid; at most 5 times in 300 s, backing off 1-16 s, counted in
  `GYMGRADE_WORKER_RESTARTS`), so a broker restart never leaves the cluster without its worker.
- Distributed batch: `batch.CeleryExecutor` (entry point `gymgrade.executors: cluster`) sends task
  `gymgrade.grade_file({key, reply_to, filename, name, content (base64), seed, only, config_toml, ...})`;
  `filename` is the file's name on the batch's disk (a zip's numbered copy, `6.py`: its kind, `.py` or
  `.ipynb`), `name` its own name as shown (the batch's `file_names`, `grader.render.neutral.file_name` of
  the download's; absent from a batch of before the field, then `filename` is shown). The worker trusts
  neither: it shows `file_name(name)` (bounded) and writes the file as `uploads.grading_file_name(filename)`,
  then grades it as an upload is graded: the runner gives the child the name to show (`"name"`, when the
  file's grading name differs) and the child the grader (`grade_submission(..., name=)`). The
  worker grades it in the same child and RPUSHes `{key, report}` or `{key, error}` to the batch's Redis
  list `gymgrade:batch:<uuid>`, which the client BLPOPs (Celery's Redis result backend is not used: it
  gives up for good after a broker outage). After a broker outage the client sends the outstanding files
  again; Ctrl-C revokes them. `config_toml` is the configuration file's text read once when the batch is
  sent (`configuration_text`), refused with a `ConfigError` unless it still validates to the plan's
  configuration (its `config_sha256`), so the cluster grades with the configuration the batch checked.
"""
