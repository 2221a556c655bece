"""Output formats of a grading: one module per format, chosen by name from `grader.render.registry`.

The formats in detail:

A report is presented in several formats, each a function of the report (and, for figures, of the
configuration):

- text: the live progress lines (`grader/render/progress.py`: a line per finished check, or a one-line bar)
  and the summary `gymgrade check` prints (`grader/render/text.py`);
- JSON: `Report.to_json()` (`gymgrade check --json`, `--output`, every `gymgrade grade` report file;
  `grader/render/report_json.py`);
- Gradescope's results.json: `grader.render.gradescope.results` (the autograder itself:
  `grader.cli.gradescope`);
- the HTML report and its figures:
  - `grader/lab/showcase.py`: `showcase_episode(rule, records) -> EpisodeReplay | None` (pure; `rule` is the
    problem declaration's `showcase`, a `ShowcaseRule`), called by
    `grader.grading.execution.run_problem`: `ProblemResult.replay` (`EpisodeReplay(label, env_id, reset_seed,
    actions, length, total_reward)`, declared in `grader/report.py`) is the CartPole episode that ended
    first, the MountainCar episode that took longest, and the last Taxi episode of the first call; only
    episodes the trusted replay reproduced, of the problem's own env ids, without student kwargs or reset
    options (`SHORTEST_CARTPOLE`, `LONGEST_MOUNTAIN_CAR`, `LAST_TAXI_OF_FIRST_CALL`).
  - e plotting stack draws every figure gymgrade shows (HTML report, class report, the service's page):
    `grader/lab/plots.py` holds the look (`PLOT_SIZE`, `PLOT_DPI`, the colours), the canvas (`new_canvas()`,
    `new_plot()`: matplotlib's Agg canvas, no pyplot) and the plotters problems declare (`plot`, a function of
    the result and the problem's settings); `grader/render/figures.py` encodes them (`png_figure(...) ->
    Figure`, `Figure.data_uri()`), draws a problem's figures (`problem_figures(result, config) ->
    list[Figure]`, `all_figures(...)`: its plot, then `replay_gif(EpisodeReplay)`, headless `rgb_array` in the
    grader's gymnasium; `MAX_GIF_FRAMES`, `MAX_GIF_WIDTH`, `GIF_COLOURS`);
    `grader/classroom/report/figures.py` draws the class's two plots on the same canvas.
    `grader/render/html.py`: `render_html(report, config) -> str` (template
    `grader/render/templates/report.html`, images as `data:` URIs, a CSP meta with the stylesheet's sha256).
    The service's page shows the same figures, byte for byte, through `api.web.page_figures(problems,
    edition)` (each problem drawn once by `problem_figures` and cached; CSP unchanged: `img-src 'self'
    data:`).
- the class-level outputs: `grader/classroom/report/` (the class page and `class.json`), the gradebooks of
  `grader/classroom/gradebooks.py`, and the similarity report of `grader/classroom/similarity/`.

`gymgrade check --format text|json|gradescope|html` (`--json` = `--format json`) chooses the format.

`grader/render/` holds one module per output format of a report, each a pure function of the report (and the
configuration it was graded with, whose bars the HTML report's plots draw) to the exact text written:
`text.py` (the summary, and the notebook and isolation lines the other formats reuse), `report_json.py`,
`gradescope.py` (Gradescope's results models and `results()`), `html.py`. `registry.py` lists them in
`FORMATS` (`OutputFormat(render, description, live_progress)`), from which `gymgrade check --format` takes its
choices and help; the CLI only parses, grades, picks a format and writes it (`--output` and `--html` write the
`json` and `html` formats too). `csp.py` declares the one Content-Security-Policy of every page gymgrade
writes (`content_security_policy(style, images=True)`: nothing but the page's own stylesheet, pinned by hash,
and, for pages with plots, `data:` images); every page (student report, class report, similarity) extends one
frame, `grader/render/templates/page.html`, drawn by `page.page_environment()`. `grader/cli/gradescope.py`
keeps the autograder zip and `run_autograder`. What the text summary prints and every `output` of Gradescope's
results pass through `grader.render.neutral.display_block` (the one place that declares which characters are
shown inert: controls but line breaks and tabs, bidi overrides, as U+FFFD), so an escape sequence a student's
code raised or printed reaches no terminal or page; the report keeps it. Class-level outputs take a class
rather than one report and keep their own tables in the same layer: the class page and `class.json`
(`grader/classroom/report/`) and the LMS gradebooks (`GRADEBOOKS` in `grader/classroom/gradebooks.py`).
"""
