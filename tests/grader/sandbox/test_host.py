"""The platform facts (`grader.sandbox.host`) and how a child is started and read (`process_model`)."""

from __future__ import annotations

import os

import pytest
from marker_layer import MarkerLayer

import grader.sandbox.isolation as isolation
from grader.sandbox import process_model
from grader.sandbox.host import HOST, Feature, Host, signal_number, usable_cpus
from grader.sandbox.isolation import probe_isolation, registry

WINDOWS = Host("Windows", frozenset({Feature.WINDOWS_HANDLES}))
MACOS = Host("macOS", frozenset({Feature.POSIX_PROCESSES, Feature.RESOURCE_LIMITS, Feature.USER_IDS}))


@pytest.mark.parametrize(
    ("host", "needs", "detail"),
    [
        (
            WINDOWS,
            (Feature.RESOURCE_LIMITS,),
            "not available on this system (Windows without resource limits (the resource module))",
        ),
        (
            MACOS,
            (Feature.LINUX_KERNEL,),
            "not available on this system (macOS without Linux kernel features "
            "(/proc, cgroups, namespaces, seccomp, Landlock))",
        ),
        (
            WINDOWS,
            (Feature.USER_IDS, Feature.POSIX_PROCESSES),
            "not available on this system (Windows without user ids (os.geteuid, the pwd module); "
            "POSIX processes (fork, inherited descriptors, sessions, SIGKILL))",
        ),
    ],
    ids=["windows-rlimits", "macos-linux-layers", "two-missing"],
)
def test_a_missing_feature_is_named_with_the_system(
    host: Host, needs: tuple[Feature, ...], detail: str
) -> None:
    assert host.lacking(needs) == needs
    assert host.unavailable_detail(needs) == detail


@pytest.mark.parametrize("host", [WINDOWS, MACOS], ids=["windows", "macos"])
def test_every_layer_the_system_cannot_run_is_reported_unprobed(
    monkeypatch: pytest.MonkeyPatch, host: Host
) -> None:
    marker = MarkerLayer(needs=(Feature.LINUX_KERNEL,), guards="the marker's limits")
    layers = (*registry.LAYERS, marker)
    monkeypatch.setattr(registry, "LAYERS", layers)
    monkeypatch.setattr(isolation, "HOST", host)
    report = probe_isolation()
    assert marker.outer_seen == []
    assert report.layer("marker").detail == (
        f"not available on this system ({host.system} without Linux kernel features "
        "(/proc, cgroups, namespaces, seccomp, Landlock)): the marker's limits not enforced"
    )
    unavailable = {layer.name for layer in report.layers if "not available on this system" in layer.detail}
    expected = {"cgroup", "bubblewrap", "seccomp", "landlock", "marker"}
    if host is WINDOWS:
        expected |= {"privileges", "rlimits"}
    assert unavailable == expected
    assert not report.full
    if host is WINDOWS:
        assert report.layer("rlimits").detail == (
            "not available on this system (Windows without resource limits (the resource module)): "
            "the CPU-time, memory, file-size and open-file limits not enforced"
        )


def test_this_linux_machine_offers_what_the_sandbox_uses() -> None:
    assert HOST.system == "Linux"
    assert HOST.has(Feature.POSIX_PROCESSES) and HOST.has(Feature.LINUX_KERNEL)
    assert process_model.MODEL == "posix" and process_model.ENDS_WHOLE_TREE
    assert usable_cpus() == len(os.sched_getaffinity(0))
    assert signal_number("SIGKILL") == 9
    assert signal_number("SIGNOSUCHTHING") is None


def test_a_pipe_is_read_as_far_as_it_holds_data_then_to_its_end() -> None:
    read_end, write_end = os.pipe()
    try:
        process_model.make_nonblocking(read_end)
        assert process_model.read_available(read_end, 1024) is None
        os.write(write_end, b"abc")
        assert process_model.read_available(read_end, 2) == b"ab"
        assert process_model.read_available(read_end, 1024) == b"c"
        os.close(write_end)
        write_end = -1
        assert process_model.read_available(read_end, 1024) == b""
    finally:
        os.close(read_end)
        if write_end >= 0:
            os.close(write_end)


def test_a_system_without_pass_fds_refuses_extra_descriptors(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(process_model, "MODEL", "inherited")
    with pytest.raises(OSError, match=r"cannot pass the descriptors \[7\] to a child"):
        process_model.start(["true"], env={}, cwd=None, channel=(), extra_fds=(7,))
