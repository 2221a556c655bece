"""The platform facts (`grader.sandbox.host`) and how a child is started and read (`process_model`)."""

from __future__ import annotations

import os
import subprocess
import sys

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
    host = Host(host.system, host.features & HOST.features)  # a layer this machine lacks is never probed
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
    if host.system == "Windows":
        expected |= {"privileges", "rlimits"}
    assert unavailable == expected
    assert not report.full
    if host.system == "Windows":
        assert report.layer("rlimits").detail == (
            "not available on this system (Windows without resource limits (the resource module)): "
            "the CPU-time, memory, file-size and open-file limits not enforced"
        )


EXPECTED_MODELS = {
    "Linux": (
        "posix",
        {
            Feature.POSIX_PROCESSES,
            Feature.RESOURCE_LIMITS,
            Feature.USER_IDS,
            Feature.LINUX_KERNEL,
            Feature.FILE_LOCKS,
        },
    ),
    "macOS": (
        "posix",
        {Feature.POSIX_PROCESSES, Feature.RESOURCE_LIMITS, Feature.USER_IDS, Feature.FILE_LOCKS},
    ),
    "Windows": ("windows", {Feature.WINDOWS_HANDLES}),
}


def test_this_system_is_served_by_its_own_process_model() -> None:
    model, features = EXPECTED_MODELS[HOST.system]
    assert model == process_model.MODEL
    assert features <= HOST.features
    assert not HOST.has(Feature.LINUX_KERNEL) or HOST.system == "Linux"
    assert 1 <= usable_cpus() <= (os.cpu_count() or 1)
    assert signal_number("SIGTERM") == 15
    assert signal_number("SIGNOSUCHTHING") is None
    assert (signal_number("SIGKILL") == 9) == (HOST.system != "Windows")


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


def test_a_running_process_exists_and_an_ended_one_does_not() -> None:
    ended = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, check=True
    )
    assert process_model.exists(os.getpid()) is True
    assert process_model.exists(int(ended.stdout)) is False
