"""Every blastfrac kernel module compiles for the GPUs the project targets (sm_90: H100, H200), on a machine
without one (issue 14, item 6).

A GPU is lent to few sessions, for 15 minutes. Warp compiles CUDA code with its bundled NVRTC and needs no driver
for that (``wp.compile_aot_module`` with an ``arch``). So a CUDA-only compile error would show here, in CI, and not
during the minutes on the device. This checks that the kernels compile; whether they run, and what they give, is
``benchmarks/gpu_check.py`` on the device.
"""

from __future__ import annotations

import pytest
import warp as wp

from blastfrac._warp import init_warp, kernel_module_names

#: the target architecture: H100 / H200 (compute capability 9.0)
ARCH = 90

#: modules that must be among those found (the step's kernels), so that an empty discovery cannot pass
CORE = {"blastfrac.cdem.kernels_spring", "blastfrac.cdem.kernels_element", "blastfrac.cdem.kernels_integrate",
        "blastfrac.cdem.contact_kernels", "blastfrac.coupling.kernels_contact", "blastfrac.mpm.kernels_p2g",
        "blastfrac.mpm.kernels_g2p", "blastfrac.mpm.kernels_eos"}


def _cuda_compiler() -> bool:
    """True where this Warp build can compile CUDA code (its NVRTC); a CPU-only build (macOS) cannot."""
    try:
        from warp._src.context import runtime
    except ImportError:
        return False
    init_warp()
    return bool(getattr(runtime, "is_cuda_enabled", False))


MODULES = kernel_module_names()


def test_discovery_finds_the_step_kernels():
    assert CORE <= set(MODULES), sorted(CORE - set(MODULES))


@pytest.mark.skipif(not _cuda_compiler(), reason="this Warp build has no CUDA compiler (NVRTC)")
@pytest.mark.parametrize("name", MODULES)
def test_module_compiles_for_sm90(name, tmp_path):
    paths = wp.compile_aot_module(name, arch=ARCH, module_dir=tmp_path)
    cubins = [p for p in map(str, paths) if p.endswith(f".sm{ARCH}.cubin")]
    assert cubins, paths
    for p in cubins:
        with open(p, "rb") as f:
            assert f.read(4) == b"\x7fELF"          # a CUDA binary is an ELF image
