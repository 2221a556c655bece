"""The reference index cache: each reference file is indexed once, keyed by its bytes.

An entry is ``<blake2b of the file's text and INDEX_VERSION>.json`` holding its `IndexedFile`; a new
version of the normaliser or the winnowing changes ``INDEX_VERSION`` and with it every key. An entry
that cannot be read is indexed again and rewritten, never trusted.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

from pydantic import ValidationError

from grader.similarity.document import IndexedFile
from grader.similarity.winnow import WINDOW, K

INDEX_VERSION = f"1-k{K}-w{WINDOW}"


def default_cache_dir() -> Path:
    """``$XDG_CACHE_HOME/gymgrade/similarity`` (``~/.cache/gymgrade/similarity`` by default)."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "gymgrade" / "similarity"


def cache_key(text: str) -> str:
    """The entry name of a file's text."""
    return hashlib.blake2b(f"{INDEX_VERSION}\0{text}".encode(), digest_size=20).hexdigest()


class IndexCache:
    """Indexed reference files on disk, one JSON file per distinct text."""

    def __init__(self, directory: Path) -> None:
        self.directory = directory
        self.hits = 0
        self.misses = 0

    def get(self, text: str) -> IndexedFile | None:
        """The cached index of ``text``, or None when there is none (or it is unreadable)."""
        path = self.directory / f"{cache_key(text)}.json"
        try:
            indexed = IndexedFile.model_validate_json(path.read_bytes())
        except (OSError, ValidationError, ValueError):
            self.misses += 1
            return None
        self.hits += 1
        return indexed

    def put(self, text: str, indexed: IndexedFile) -> None:
        """Store an index (written whole, then renamed, so a concurrent reader never sees half an entry)."""
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
            path = self.directory / f"{cache_key(text)}.json"
            partial = path.with_suffix(f".{os.getpid()}.tmp")
            partial.write_text(indexed.model_dump_json(), encoding="utf-8")
            partial.replace(path)
        except OSError:
            pass  # a cache that cannot be written only costs time: the comparison itself is unaffected
