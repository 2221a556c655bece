"""One child's start: the active layers, in `registry.LAYERS` order, each add their part to a `LaunchSpec`,
composed into a `Launch` (the contract, `grader.sandbox.isolation.layer`, declares both)."""

from __future__ import annotations

from grader.sandbox import process_model
from grader.sandbox.isolation import registry
from grader.sandbox.isolation.filesystem import harness_tree, python_paths
from grader.sandbox.isolation.layer import IsolationReport, Launch, LaunchSpec
from grader.sandbox.limits import Limits


def build_launch(
    report: IsolationReport,
    limits: Limits,
    *,
    submission: bytes,
    submission_name: str,
    requests_fd: int,
    results_fd: int,
    import_seed: int,
    shown_name: str = "",
) -> Launch:
    """The command starting one child: every active layer of `report` applied in order, outermost first.
    ``shown_name`` (the file's own name in the child's messages, plain data, never a path) is passed as
    ``--name`` when given.

    Raises:
        OSError: when a layer that was probed as active fails now (the caller reports a sandbox error).
    """
    spec = LaunchSpec(report, limits, python_paths(), harness_tree(), submission, submission_name)
    active = {layer.name for layer in report.layers if layer.active}
    try:
        for layer in registry.LAYERS:
            if layer.name in active:
                layer.apply(spec)
        harness_argv = [
            "--submission",
            spec.child_view().submission,
            *process_model.channel_arguments(requests_fd, results_fd),
            "--max-frame",
            str(limits.frame_bytes),
            "--seed",
            str(import_seed),
            *(("--name", shown_name) if shown_name else ()),
        ]
        return spec.compose(harness_argv)
    except BaseException:
        spec.launch.cleanup()
        raise
