"""Session settings shared by every test."""

from __future__ import annotations

import os

# The numba compile notice (encctl_gym._jit) prints on stderr when a kernel is not yet in the
# cache. Whether it is depends on what ran before on the machine, so no test's captured stderr may
# depend on it: the notice is off here, and tests/test_jit_notice.py turns it on in a subprocess.
os.environ["ENCCTL_GYM_JIT_NOTICE"] = "0"
