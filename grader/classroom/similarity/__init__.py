"""Template-aware code similarity across a class and against known solutions, ranked for a person to read.

It never changes a grade and never accuses: a flagged pair is a pair whose code shares more than
independent solutions of this lab share, with the matched code shown side by side.

In detail (pure core, thin shell; nothing here runs student code or changes a grade):

- `sources.py`: `submissions_from(path, layout=None, scratch=None, rule=None) -> ClassSources`, the one
  class-layout adapter: it calls `grader.classroom.discover` (the download as `gymgrade grade` reads it) and
  `sources_of(ClassDownload) -> ClassSources(layout, submissions=[(identity, [paths])], skipped=[
  UnreadableFile])` keeps each submission's `is_candidate` files, the graded one first, and lists refused,
  unattributed and nothing-to-compare files with their reason. `references_from`, `read_source(path) ->
  SourceText | Unreadable` (bounded: `MAX_COMPARED_BYTES` = 200 KB, `MAX_NOTEBOOK_BYTES`; read with
  `grader.submission.untrusted_file.read_untrusted`, so links are never followed; notebooks' code cells from
  the bounded reader, `grader.submission.notebook.read_notebook`, a cell that does not parse blanked and
  noted).
- `normalise.py`: `normalise(source) -> NormalisedSource(units, remarks, constants)` via `ast`; one `Unit`
  (tokens, lines, `shape` digest) per function/method plus one for module code.
- `winnow.py`: `kgram_hashes`, `winnow`, `fingerprints(units)` (K=16, WINDOW=8; blake2b-per-token
  Karp-Rabin hashes, stable across processes). Written here, not taken from copydetect (no hook for AST
  tokens, per-function units or process-stable hashes).
- `template.py`: `load_template(paths) -> Template(shapes, fingerprints, remarks, names)`; bundled templates
  in `templates/*.py.txt` (`opengym_classic.py.txt` equals `submissions/template.py`, a test pins it).
- `document.py`: `index_text(text, name) -> IndexedFile` (what one file contributes; what the cache stores),
  `build_document(identity, is_reference, indexed, template) -> Document` (template removed).
- `cache.py`: `IndexCache(dir)`, entries keyed by blake2b(`INDEX_VERSION`, text), each a `CacheEntry(sha256
  of the text, index)`: used only when the folder and the entry are the user's own and writable by no one
  else, read with `O_NOFOLLOW`, checked (`inconsistency(index)`, the digest); a bad entry is indexed again and
  noted (`IndexCache.notes`, added to the report's notes). Written under a random name with
  `O_CREAT|O_EXCL|O_NOFOLLOW` through the folder's descriptor, then renamed (flags behind `getattr`, so it
  imports on Windows, where the ownership checks are skipped).
- `frequency.py` (common fingerprints, rare remarks/constants/typos), `score.py` (numpy inverted-index pair
  counts, `pair_score`, `fragments`), `evidence.py`, `typos.py`, `behaviour.py` (`wrong_results(Report)`:
  the hook for shared wrong behaviour), `clusters.py`, `compare.py` (`flagged_pairs`, `all_scores`,
  `build_report -> SimilarityReport`), `report.py` (pydantic models).
- Shell: `run.py` (`run_similarity(class_dir | ClassSources, references, ..., workers=None)`: reads and
  indexes in batches of 64 documents, read in `workers` threads (a notebook waits for its bounded reader) and
  indexed in a process pool), `csv_output.py`, `html_output.py` (+ `templates/similarity.html`, CSP from
  `grader.render.csp`, without images), `command.py` (`gymgrade similarity [--layout]`, registered in
  `grader/cli/__init__.py`; it owns the zip scratch folder for the whole run, as the page re-reads the files;
  `write_similarity(sources, out, references, reports=DIR)` is shared with `gymgrade grade --similarity`,
  which calls it with `sources_of(download)` inside grading's scratch folder and its own `--out` as the
  reports folder). `behaviour.load_wrong_results` names reports with `grader.grading.batch.identity_stem`, the
  batch's own naming.
- Corpus: `submissions/similarity/` (`expected.toml` names the copied pairs, the ring, the template-only).
"""
