#!/usr/bin/env bash
# Issue 14 item 6 on a lent GPU machine, run from the repository root there: unpack the dependencies carried in
# .gpu/p1 ... .gpu/pN (benchmarks/gpu_pack.py: one call per part on the warm machine, this script in the call that
# carries the last), then gpu_check.py on the GPU alone (its CPU side runs here afterwards, at no device time:
# python benchmarks/gpu_check.py --compare <the fetched gpu_check.json>). Extra arguments go to gpu_check.py.
set -euo pipefail
cd "$(dirname "$0")/.."
# (GPU_SITE and GPU_PACK: where to unpack, and the parts; gpu_pack.py --check sets them to rehearse this here)
SITE=${GPU_SITE:-/tmp/site}
if [ ! -d "$SITE/warp" ]; then
    python3 benchmarks/gpu_pack.py --unpack "$SITE" --parts "${GPU_PACK:-.gpu}"
fi
export PYTHONPATH="$SITE:$PWD/src"
# the libraries libgmsh.so links against that this machine lacks, from the pack (gpu_pack.bundle_system_libraries):
# only those, so that none of the image's own is shadowed
mkdir -p "$SITE/syslibs_used"
known=$(ldconfig -p)
for f in "$SITE"/syslibs/*; do
    n=$(basename "$f")
    grep -q "^[[:space:]]*$n " <<<"$known" || ln -sf "$f" "$SITE/syslibs_used/$n"
done
echo "bundled libraries used: $(ls "$SITE/syslibs_used" | tr '\n' ' ')"
export LD_LIBRARY_PATH="$SITE/syslibs_used${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
# (not fatal: without gmsh the MPM throughput still runs, and gpu_check records what failed)
python3 -c "import gmsh; gmsh.initialize(); gmsh.finalize(); print('gmsh', gmsh.__version__)" || echo "gmsh FAILED"
# the pack's kernel cache: blastfrac's modules compiled for sm_90 at packing time (gpu_pack.cuda_cache)
export WARP_CACHE_PATH="$SITE/warp_cache"
nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv,noheader || true
python3 -c "import warp as wp; wp.init(); print('warp', wp.__version__, [d.name for d in wp.get_cuda_devices()])"
python3 benchmarks/gpu_check.py --device cuda:0 --skip-cpu --out "${OUT:-out/gpu_check}" "$@"
