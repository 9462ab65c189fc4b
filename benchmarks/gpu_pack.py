"""Carry blastfrac's Python dependencies to a lent GPU machine, and unpack them there (issue 14, item 6).

The lent machines (``../.library/device``: H100 / H200, Python 3.12, no network) hold numpy, scipy, matplotlib and
rich, but not Warp, gmsh, pydantic, meshio or tomli-w, and a call carries at most 64 MiB, the working tree
included (~21 MB). Warp's wheel alone is 149 MB (its CUDA library, 299 MB unpacked). So:

1. here, at no device time: ``python benchmarks/gpu_pack.py`` (``make gpu-pack``) downloads the wheels of the
   versions installed here for CPython 3.12 on manylinux x86-64 and installs them into a staging folder, with the
   shared libraries libgmsh.so links against (``bundle_system_libraries``) and a Warp kernel cache of every blastfrac
   module compiled for sm_90 (``cuda_cache``); it drops what a run does not read (Warp's examples, gmsh's docs and
   headers) and writes the folder as one xz-compressed tar split into parts that each fit a call beside the working
   tree, ``.gpu/p1`` … ``.gpu/pN`` (``.gpu/`` is in .gitignore; 3 parts and ~4 minutes on 2 cores);
2. on the device, one call per part while the machine stays warm (it keeps ignored paths between calls; it is given
   back after 30 s idle): ``run(command="true", carry=[".gpu/p1"])``, … and the last part with the work itself:
   ``run(command="bash benchmarks/gpu_device.sh", carry=[".gpu/pN"], timeout_s=...)``;
3. ``gpu_device.sh`` calls ``python3 benchmarks/gpu_pack.py --unpack /tmp/site`` (standard library only: it joins
   the parts in order and checks the total size and SHA-256 written beside them), sets PYTHONPATH, LD_LIBRARY_PATH
   (the bundled libraries the machine lacks) and WARP_CACHE_PATH, and runs ``gpu_check.py --skip-cpu``; fetch its
   ``gpu_check.json`` and run the CPU side of the agreement check here
   (``python benchmarks/gpu_check.py --compare gpu_check.json``), at no device time.

``python benchmarks/gpu_pack.py --python-version 3.11 --check`` builds a pack for this machine's Python and runs
``gpu_device.sh`` with it on the CPU (``--device cpu --quick``): the parts joined and unpacked, the libraries and
the kernel cache set up, ``gpu_check.py``'s parts run from the unpacked folder; then Warp, gmsh, pydantic, meshio and
tomli-w must import from there, with every bundled library on LD_LIBRARY_PATH resolved there (``ldd``): the device's
call rehearsed at no device time.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tarfile
import tempfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACK = ROOT / ".gpu"
#: the distributions blastfrac needs that the lent machines lack (``../.library/device/KINDS.md``)
NEEDED = ("warp-lang", "gmsh", "meshio", "pydantic", "pydantic-core", "annotated-types", "typing-inspection",
          "typing-extensions", "tomli-w")
#: platform tags pip may match for the device's x86-64 Linux (the device README's list)
PLATFORMS = ("manylinux_2_28_x86_64", "manylinux_2_27_x86_64", "manylinux_2_24_x86_64", "manylinux_2_17_x86_64",
             "manylinux2014_x86_64", "manylinux1_x86_64")
#: what no run reads: dropped from the staging folder before packing
DROP = ("warp/examples", "warp/tests", "share/doc", "include", "lib/cmake")


#: the pack's Warp kernel cache (gpu_device.sh points WARP_CACHE_PATH at it): every blastfrac kernel module compiled
#: for sm_90 here, so that the device loads them instead of compiling them (~30 s of its time)
CACHE = "warp_cache"
#: the lent GPUs' architecture (H100, H200)
ARCH = 90


def cuda_cache(cache: Path) -> None:
    """Compile every blastfrac kernel module for ARCH into the kernel cache ``cache`` (Warp's own layout, by this
    machine's Warp, which is the packed version): a module's name and hash are those the device computes for the
    same source, so it finds them; a miss only costs the compile."""
    code = ("import sys, warp as wp; from blastfrac._warp import kernel_module_names\n"
            "[wp.compile_aot_module(n, arch=int(sys.argv[1])) for n in kernel_module_names()]")
    env = {**os.environ, "WARP_CACHE_PATH": str(cache)}
    subprocess.run([sys.executable, "-c", code, str(ARCH)], env=env, check=True, capture_output=True)


#: where the pack keeps the shared libraries libgmsh.so links against (gpu_device.sh puts those the device lacks on
#: LD_LIBRARY_PATH)
SYSLIBS = "syslibs"
#: the C and C++ run-time libraries every Linux has: not bundled (the device's own must be used)
RUNTIME = ("libc.so", "libm.so", "libpthread.so", "libdl.so", "librt.so", "ld-linux", "libstdc++.so", "libgcc_s.so",
           "linux-vdso")


def bundle_system_libraries(stage: Path) -> list[str]:
    """Copy into stage/SYSLIBS the shared libraries libgmsh.so needs (X11, GL, fontconfig… as this machine resolves
    them, ``ldd``), the C/C++ run time excepted: the lent machines' image is made for CUDA, not for a desktop, and
    may lack them. Built on an older glibc than the device's (Debian 12 here: 2.36), so they load there."""
    lib = next((stage / "lib").glob("libgmsh.so*"))
    out = subprocess.run(["ldd", str(lib)], capture_output=True, text=True, check=True).stdout
    (stage / SYSLIBS).mkdir(exist_ok=True)
    names = []
    for line in out.splitlines():
        f = line.split()
        if len(f) >= 3 and f[1] == "=>" and f[2].startswith("/") and not any(r in f[0] for r in RUNTIME):
            shutil.copy2(os.path.realpath(f[2]), stage / SYSLIBS / f[0])
            names.append(f[0])
    return names


def installed_versions() -> dict[str, str]:
    """The installed version of each NEEDED distribution (this machine's environment is the tested one)."""
    from importlib.metadata import version

    return {name: version(name) for name in NEEDED}


def build(python_version: str, part_mib: int, out: Path = PACK) -> list[Path]:
    """Download, stage and pack the dependencies for CPython ``python_version``; returns the part folders."""
    pins = [f"{n}=={v}" for n, v in installed_versions().items()]
    plat = [a for p in PLATFORMS for a in ("--platform", p)]
    with tempfile.TemporaryDirectory() as tmp:
        wheels, stage = Path(tmp) / "wheels", Path(tmp) / "site"
        common = ["--no-deps", "--only-binary=:all:", "--python-version", python_version, "--implementation", "cp",
                  *plat]
        subprocess.run([sys.executable, "-m", "pip", "download", "-q", *common, "-d", str(wheels), *pins], check=True)
        subprocess.run([sys.executable, "-m", "pip", "install", "-q", *common, "--no-index", "--no-compile",
                        "--target", str(stage), *map(str, sorted(wheels.glob("*.whl")))], check=True)
        # pip --target keeps a wheel's platlib and scripts but not its data folder's lib/ (gmsh's libgmsh.so, which
        # gmsh.py looks for in <site>/lib): copy those libraries in from the wheels
        for whl in wheels.glob("*.whl"):
            with zipfile.ZipFile(whl) as z:
                for info in z.infolist():
                    parts = info.filename.split("/")
                    if len(parts) == 4 and parts[0].endswith(".data") and parts[1:3] == ["data", "lib"] and parts[3]:
                        dst = stage / "lib" / parts[3]
                        dst.parent.mkdir(exist_ok=True)
                        dst.write_bytes(z.read(info))
        for rel in DROP:
            shutil.rmtree(stage / rel, ignore_errors=True)
        cuda_cache(stage / CACHE)
        bundle_system_libraries(stage)
        blob = Path(tmp) / "site.tar.xz"
        # xz from the command line uses both cores (Python's lzma module one)
        with open(blob, "wb") as f:
            tar = subprocess.Popen(["tar", "-C", str(stage), "-cf", "-", "."], stdout=subprocess.PIPE)
            subprocess.run(["xz", "-T0", "-6", "-c"], stdin=tar.stdout, stdout=f, check=True)
            if tar.wait() != 0:
                raise RuntimeError("tar failed")
        return write_parts(blob, out, part_mib << 20, {"python": python_version, "pins": pins})


def write_parts(blob: Path, out: Path, part_bytes: int, meta: dict) -> list[Path]:
    """Split the file ``blob`` into folders out/p1 … out/pN of one part each (at most ``part_bytes``), the last with
    manifest.json: ``meta`` and the blob's size, SHA-256 and part count (what ``unpack`` checks)."""
    shutil.rmtree(out, ignore_errors=True)
    parts = []
    with open(blob, "rb") as f:
        while chunk := f.read(part_bytes):
            d = out / f"p{len(parts) + 1}"
            d.mkdir(parents=True)
            (d / f"part{len(parts) + 1:02d}").write_bytes(chunk)
            parts.append(d)
    manifest = {**meta, "bytes": blob.stat().st_size, "sha256": hashlib.sha256(blob.read_bytes()).hexdigest(),
                "parts": len(parts)}
    (parts[-1] / "manifest.json").write_text(json.dumps(manifest, indent=1))
    return parts


def tree_bytes() -> int:
    """Bytes of what a device call sends besides the carried paths: tracked and untracked-not-ignored files."""
    names = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=ROOT,
                           capture_output=True, check=True).stdout.split(b"\0")
    return sum((ROOT / n.decode()).stat().st_size for n in names if n and (ROOT / n.decode()).is_file())


def unpack(target: Path, src: Path = PACK) -> dict:
    """Join the parts in order, check size and SHA-256 against the manifest, and extract into ``target``. Standard
    library only (it runs on the device before anything is installed)."""
    found = list(src.glob("p*/manifest.json"))
    if not found:
        raise SystemExit(f"no manifest.json under {src}: carry the last part (.gpu/pN) as well")
    manifest = json.loads(found[0].read_text())
    parts = sorted(src.glob("p*/part*"), key=lambda p: p.name)
    if len(parts) != manifest["parts"]:
        raise SystemExit(f"{len(parts)} of {manifest['parts']} parts here: carry each .gpu/pK on a warm machine")
    h, n = hashlib.sha256(), 0
    with tempfile.TemporaryFile() as f:
        for p in parts:
            b = p.read_bytes()
            h.update(b)
            n += len(b)
            f.write(b)
        if n != manifest["bytes"] or h.hexdigest() != manifest["sha256"]:
            raise SystemExit(f"the parts do not join to the pack ({n} of {manifest['bytes']} bytes, or the digest)")
        f.seek(0)
        target.mkdir(parents=True, exist_ok=True)
        with tarfile.open(fileobj=f, mode="r:xz") as t:
            t.extractall(target, filter="data") if sys.version_info >= (3, 12) else t.extractall(target)
    return manifest


def check(python_version: str, part_mib: int) -> None:
    """Build a pack for this Python and rehearse the device's call with it, at no device time: ``gpu_device.sh`` joins
    the parts, unpacks them, sets up the libraries and the kernel cache and runs ``gpu_check.py --quick`` on the CPU,
    with the packages taken from the unpacked folder (this environment's ``python3`` on PATH supplies numpy, scipy,
    matplotlib and rich, as the device's image does); then libgmsh's bundled libraries must resolve from the pack."""
    out = Path(tempfile.mkdtemp(prefix="gpu_pack_"))
    try:
        parts = build(python_version, part_mib, out / "pack")
        print(f"{len(parts)} parts:", ", ".join(f"{p.name} {sum(f.stat().st_size for f in p.iterdir()) / 2**20:.1f} MiB"
                                                for p in parts))
        env = {**os.environ, "GPU_PACK": str(out / "pack"), "GPU_SITE": str(out / "site"), "OUT": str(out / "gpu"),
               "PATH": os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])}
        subprocess.run(["bash", str(ROOT / "benchmarks" / "gpu_device.sh"), "--device", "cpu", "--quick"], env=env,
                       check=True)
        res = json.loads((out / "gpu" / "gpu_check.json").read_text())
        assert not res["errors"] and len(res["runs"]) == 4 and res["mpm"] and res["cdem"], res["errors"]
        print(f"gpu_device.sh: {len(res['runs'])} runs and both throughputs, no part failed")
        # the packages came from the unpacked folder, not this environment
        code = ("import sys, warp as wp, gmsh, pydantic, meshio, tomli_w\n"
                "assert all(m.__file__.startswith(sys.argv[1]) for m in (wp, gmsh, pydantic, meshio, tomli_w))\n"
                "print('pack ok: warp', wp.__version__, 'gmsh', gmsh.__version__, 'from', sys.argv[1])")
        # every bundled library on the path (the device puts only those it lacks there): they must serve libgmsh
        env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(out / "site"), str(ROOT / "src")]),
               "LD_LIBRARY_PATH": str(out / "site" / SYSLIBS)}
        lib = next((out / "site" / "lib").glob("libgmsh.so*"))
        resolved = subprocess.run(["ldd", str(lib)], env=env, capture_output=True, text=True, check=True).stdout
        bundled = {p.name for p in (out / "site" / SYSLIBS).iterdir()}
        wrong = [ln.split()[0] for ln in resolved.splitlines()
                 if ln.split() and ln.split()[0] in bundled and str(out / "site" / SYSLIBS) not in ln]
        assert bundled and not wrong, (sorted(bundled), wrong)
        print(f"libgmsh's {len(bundled)} bundled libraries resolve from the pack")
        subprocess.run([sys.executable, "-c", code, str(out / "site")], env=env, check=True)
    finally:
        shutil.rmtree(out, ignore_errors=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--python-version", default="3.12", help="the device's Python (KINDS.md: 3.12)")
    ap.add_argument("--part-mib", type=int, default=None,
                    help="largest part [MiB]; default: what a call's 64 MiB leaves beside the working tree, less 1")
    ap.add_argument("--unpack", metavar="DIR", help="on the device: join the parts and extract them into DIR")
    ap.add_argument("--parts", metavar="DIR", default=str(PACK), help="with --unpack: where the parts are (.gpu)")
    ap.add_argument("--check", action="store_true", help="build, unpack and import a pack here (scratch folders)")
    a = ap.parse_args(argv)
    if a.part_mib is None and not a.unpack:
        a.part_mib = 63 - int(tree_bytes() / 2**20 + 0.999)
    if a.unpack:
        m = unpack(Path(a.unpack), Path(a.parts))
        print(f"joined {m['parts']} parts ({m['bytes'] / 2**20:.1f} MiB) and unpacked: {' '.join(m['pins'])}")
    elif a.check:
        check(a.python_version, a.part_mib)
    else:
        parts = build(a.python_version, a.part_mib)
        print("carry, one call each on a warm machine:", " ".join(str(p.relative_to(ROOT)) for p in parts))
    return 0


if __name__ == "__main__":
    sys.exit(main())
