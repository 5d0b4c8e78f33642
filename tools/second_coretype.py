"""Print the OpenBLAS core type whose kernels make test's 2-rank test run uses.

That run uses it to see another CPU's round-off, so its core type must differ from the
host's and must itself work. Haswell's kernels (AVX2 with FMA) are the first choice. OpenBLAS
0.3.34 (Debian sid) enlarges the GEMM blocking on AMD Zen 4/5 hosts that expose AVX-512 even
when another core type is forced, and ``dgemm_kernel_HASWELL`` then overruns its stack
(OpenBLAS issues 6013, 6021, 6026): plain NumPy ``A.T @ B`` with A, B of shape 384 x 81 dies with
SIGSEGV. Each candidate is therefore tried on such products in a child process first; the first
one that survives is printed, and why the ones before it were skipped goes to stderr.
Sandybridge's kernels (AVX without FMA) round differently from both Haswell's and AVX-512's.

Usage: python3 tools/second_coretype.py [CANDIDATE ...]
"""
from __future__ import annotations

import os
import subprocess
import sys

DEFAULT_CANDIDATES = ("Haswell", "Sandybridge")

# GEMM shapes (m, k, n) of the sizes the tests multiply, including the one that crashed.
PROBE = """
import numpy as np
rng = np.random.default_rng(0)
for m, k, n in [(81, 384, 81), (64, 1000, 64), (200, 2000, 200), (10, 50, 10)]:
    a = rng.uniform(size=(k, m)); b = rng.uniform(size=(k, n))
    c = a.T @ b
    assert np.allclose(c, np.einsum("ki,kj->ij", a, b))
    np.linalg.solve(np.eye(m) + c @ c.T / k**2, c[:, 0])
"""


def survives(coretype: str) -> tuple[bool, str]:
    """Whether NumPy's products run with OPENBLAS_CORETYPE=coretype, and what killed them."""
    env = dict(os.environ, OPENBLAS_CORETYPE=coretype)
    result = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True,
                            text=True, timeout=300)
    if result.returncode == 0:
        return True, ""
    reason = (f"signal {-result.returncode}" if result.returncode < 0
              else f"exit status {result.returncode}: {result.stderr.strip()[-200:]}")
    return False, reason


def main(candidates: list[str]) -> int:
    for coretype in candidates:
        ok, reason = survives(coretype)
        if ok:
            print(coretype)
            return 0
        print(f"second_coretype: OPENBLAS_CORETYPE={coretype} skipped: NumPy's matrix products "
              f"die with it on this host ({reason}); an OpenBLAS bug, not the library's",
              file=sys.stderr)
    print(f"second_coretype: none of {', '.join(candidates)} works here", file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:] or list(DEFAULT_CANDIDATES)))
