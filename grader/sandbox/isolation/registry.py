"""The isolation layers, outermost first: the one list that declares them.

Probing (`probe_isolation`) and applying (`build_launch`) both loop over `LAYERS`; the report lists the
layers in this order and each child is wrapped in it (cgroup join, then bwrap, then setpriv). Adding a
layer is one module implementing `grader.sandbox.isolation.layer.Layer` and one line here.
"""

from __future__ import annotations

from grader.sandbox.isolation.bubblewrap import BubblewrapLayer
from grader.sandbox.isolation.cgroup import CgroupLayer
from grader.sandbox.isolation.landlock import LandlockLayer
from grader.sandbox.isolation.layer import Layer
from grader.sandbox.isolation.privileges import PrivilegesLayer
from grader.sandbox.isolation.rlimits import RlimitsLayer
from grader.sandbox.isolation.seccomp import SeccompLayer

LAYERS: tuple[Layer, ...] = (
    CgroupLayer(),
    BubblewrapLayer(),
    SeccompLayer(),
    PrivilegesLayer(),
    RlimitsLayer(),
    LandlockLayer(),
)
