"""Gradescope "Export Submissions": ``assignment_{id}_export/submission_metadata.yml`` and a
``submission_{id}/`` folder per submission.

The YAML has Ruby-symbol keys (``:submitters:``, ``:name:``, ``:sid:``, ``:email:``, ``:created_at:``,
``:history:`` for earlier attempts); it is read with PyYAML's safe loader, so no tag builds an object.
Each submitter is a student (a group submission counts for each), keyed by SID, else email, else name.
Only the active submission's files are in the export; ``:history:`` is counted in the note.
"""

from __future__ import annotations

from collections import defaultdict
from datetime import datetime
from typing import Any

import yaml

from grader.classroom.errors import LayoutMismatch
from grader.classroom.layouts.protocol import Group, Grouping
from grader.classroom.model import Member, Skipped
from grader.classroom.tree import Entry, Tree

METADATA = "submission_metadata.yml"
_SafeLoader: type[yaml.SafeLoader] = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class MetadataLoader(_SafeLoader):  # type: ignore[misc,valid-type]
    """PyYAML's safe loader (the C one where PyYAML has it), reading a tagged node (``!ruby/object:...``, as
    Rails writes a time or a record) as the plain mapping, list or text under the tag: no tag builds an
    object."""


def _untagged(loader: yaml.SafeLoader, _suffix: str, node: yaml.Node) -> object:
    if isinstance(node, yaml.MappingNode):
        return loader.construct_mapping(node, deep=True)
    if isinstance(node, yaml.SequenceNode):
        return loader.construct_sequence(node, deep=True)
    return loader.construct_scalar(node)  # type: ignore[arg-type]


MetadataLoader.add_multi_constructor("!", _untagged)
MetadataLoader.add_multi_constructor("tag:yaml.org,2002:", _untagged)
MAX_METADATA_BYTES = 32 * 2**20


def metadata_entry(tree: Tree) -> Entry | None:
    """The shallowest ``submission_metadata.yml`` of the download (at its top or one folder down)."""
    found = [entry for entry in tree.entries if entry.name == METADATA and len(entry.parts) <= 2]
    return min(found, key=lambda entry: len(entry.parts)) if found else None


def _field(mapping: object, key: str) -> Any:
    """A field under its Ruby-symbol key (``:sid``) or a plain one (``sid``)."""
    if not isinstance(mapping, dict):
        return None
    return mapping.get(f":{key}", mapping.get(key))


def _text(value: object) -> str:
    return "" if value is None else str(value).strip()


def _time(value: object) -> datetime | None:
    if isinstance(value, dict):  # a tagged Rails time, read as its fields
        value = value.get("utc", value.get("time"))
    if isinstance(value, datetime):
        return value
    try:
        return datetime.fromisoformat(_text(value)) if value else None
    except ValueError:
        return None


class GradescopeLayout:
    """See the module docstring."""

    name = "gradescope"
    title = "Gradescope Export Submissions"

    def score(self, tree: Tree) -> float:
        """1 when the download has Gradescope's ``submission_metadata.yml``."""
        return 1.0 if metadata_entry(tree) is not None else 0.0

    def group(self, tree: Tree) -> Grouping:
        """A group per submission folder the metadata names, its submitters as members."""
        entry = metadata_entry(tree)
        if entry is None:
            raise LayoutMismatch(
                f"no {METADATA} at the top of the download or one folder down: a Gradescope export has "
                "assignment_{id}_export/submission_metadata.yml; pass the export's zip or folder as downloaded"  # noqa: E501
            )
        metadata = self._load(entry)
        base = len(entry.parts) - 1
        folders: dict[str, list[Entry]] = defaultdict(list)
        grouping = Grouping()
        for other in tree.entries:
            if other is entry:
                continue
            if len(other.parts) > base + 1 and other.parts[:base] == entry.parts[:base]:
                folders[other.parts[base]].append(other)
            else:
                grouping.unattributed.append(Skipped(other.relative, "outside every submission_{id} folder"))
        for key, record in sorted(metadata.items(), key=lambda item: str(item[0])):
            folder = str(key)
            members = tuple(self._member(submitter) for submitter in (_field(record, "submitters") or []))
            members = tuple(member for member in members if member.identity)
            if not members:
                grouping.unattributed += [
                    Skipped(item.relative, f"{folder} names no submitter in {METADATA}")
                    for item in folders.pop(folder, [])
                ]
                continue
            history = _field(record, "history") or []
            files = folders.pop(folder, [])
            grouping.groups.append(
                Group(
                    members,
                    [(item, "/".join(item.parts[base + 1 :])) for item in files],
                    submitted_at=_time(_field(record, "created_at")),
                    note=f"active submission; {len(history)} earlier in its history" if history else "",
                )
            )
        for folder, files in sorted(folders.items()):
            grouping.unattributed += [
                Skipped(item.relative, f"the folder {folder} is not in {METADATA}") for item in files
            ]
        return grouping

    @staticmethod
    def _load(entry: Entry) -> dict[Any, Any]:
        data = entry.path.read_bytes()[: MAX_METADATA_BYTES + 1]
        if len(data) > MAX_METADATA_BYTES:
            raise LayoutMismatch(
                f"{entry.relative} is over {MAX_METADATA_BYTES:,} bytes: not a Gradescope export's metadata"
            )
        try:
            loaded = yaml.load(data, Loader=MetadataLoader)  # a safe loader: see MetadataLoader
        except yaml.YAMLError as error:
            raise LayoutMismatch(
                f"{entry.relative} is not valid YAML ({error}): re-download the export"
            ) from error
        if not isinstance(loaded, dict):
            raise LayoutMismatch(
                f"{entry.relative} holds {type(loaded).__name__}, expected a mapping of submission_{{id}} folders"  # noqa: E501
            )
        return loaded

    @staticmethod
    def _member(submitter: object) -> Member:
        sid, email, name = (_text(_field(submitter, key)) for key in ("sid", "email", "name"))
        return Member(sid or email or name, name, email)
