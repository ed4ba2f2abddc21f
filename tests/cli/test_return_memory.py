"""glibc's retention of freed arrays and :mod:`femkit.allocator`, which hands them back: measured
on the process's resident memory (``/proc``), in fresh interpreters."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from femkit.allocator import ENVIRONMENT

#: After one 24 MB array is freed glibc serves every smaller request from its heap and keeps
#: it when freed; 40 arrays of 8 MB, each followed by a 256 kB one, are freed: how many MB
#: go back to the system?
PATTERN = """
import numpy as np
from femkit.allocator import from_environment
from femkit.cost.memory import current_rss
assert from_environment() == {tuned}
a = np.ones(3 << 20); del a
held, pins = [], []
for _ in range(40):
    held.append(np.ones(1 << 20))
    pins.append(np.ones(1 << 15))
base = current_rss()
del held
print((base - current_rss()) >> 20)
"""

linux_glibc = pytest.mark.skipif(not sys.platform.startswith("linux") or
                                 not os.confstr("CS_GNU_LIBC_VERSION").startswith("glibc"),
                                 reason="glibc's allocator (Linux) only")


def _returned_mb(tuned: bool) -> int:
    env = {k: v for k, v in os.environ.items() if not k.startswith("MALLOC_")}
    env.pop(ENVIRONMENT, None)
    if tuned:
        env[ENVIRONMENT] = "1"
    out = subprocess.run([sys.executable, "-c", PATTERN.format(tuned=tuned)], env=env,
                         capture_output=True, text=True, check=True)
    return int(out.stdout.split()[-1])


@linux_glibc
def test_freed_arrays_stay_resident_unless_the_allocator_is_tuned():
    kept, returned = _returned_mb(False), _returned_mb(True)
    assert kept < 40 and returned > 280, (kept, returned)
