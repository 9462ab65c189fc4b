"""The GPU pack's parts join back to the pack, and a missing or damaged part is refused (benchmarks/gpu_pack.py).

On a lent GPU machine the dependencies arrive in parts, one per call; a wrong join would cost the session's device
time in a confusing import error, so ``unpack`` checks the count, the size and the SHA-256 before extracting."""

from __future__ import annotations

import importlib.util
import io
import os
import tarfile
from pathlib import Path

import numpy as np
import pytest

SPEC = importlib.util.spec_from_file_location("gpu_pack", Path(__file__).parents[2] / "benchmarks" / "gpu_pack.py")
gpu_pack = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(gpu_pack)


@pytest.fixture
def pack(tmp_path):
    """A folder of three files packed as gpu_pack packs one (tar, xz), split into parts of 4 KiB."""
    rng = np.random.default_rng(7)
    files = {"a.bin": rng.bytes(9000), "sub/b.txt": b"blastfrac\n" * 300, "c.bin": rng.bytes(100)}
    blob = tmp_path / "site.tar.xz"
    with tarfile.open(blob, "w:xz") as t:
        for name, data in files.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            t.addfile(info, io.BytesIO(data))
    parts = gpu_pack.write_parts(blob, tmp_path / "pack", 4096, {"pins": ["x==1"]})
    return files, parts, tmp_path


def test_parts_join_back(pack):
    files, parts, tmp = pack
    assert len(parts) == -(-os.path.getsize(tmp / "site.tar.xz") // 4096) >= 3
    manifest = gpu_pack.unpack(tmp / "site", tmp / "pack")
    assert manifest["parts"] == len(parts) and manifest["pins"] == ["x==1"]
    for name, data in files.items():
        assert (tmp / "site" / name).read_bytes() == data


def test_a_missing_part_is_refused(pack):
    _, parts, tmp = pack
    for f in parts[1].iterdir():
        f.unlink()
    with pytest.raises(SystemExit, match="parts here"):
        gpu_pack.unpack(tmp / "site", tmp / "pack")


def test_a_damaged_part_is_refused(pack):
    _, parts, tmp = pack
    part = next(p for p in parts[0].iterdir() if p.name.startswith("part"))
    data = bytearray(part.read_bytes())
    data[100] ^= 0x01
    part.write_bytes(bytes(data))
    with pytest.raises(SystemExit, match="do not join"):
        gpu_pack.unpack(tmp / "site", tmp / "pack")


def test_the_last_part_is_required(pack):
    _, parts, tmp = pack
    for f in parts[-1].iterdir():
        f.unlink()
    with pytest.raises(SystemExit, match="manifest"):
        gpu_pack.unpack(tmp / "site", tmp / "pack")
