"""Issue 34 items 16 and 18: NPZ readers bound the shapes the .npy headers declare, and a corrupt
archive is a package error (plant files and precomputation files)."""

from __future__ import annotations

import io
import json
import resource
import zipfile
from pathlib import Path

import numpy as np
import pytest
from numpy.lib import format as npy_format

from encctl_gym._npz import read_npz
from encctl_gym.cli import main
from encctl_gym.cryptanalysis import get_breaker
from encctl_gym.cryptanalysis.precomputation_file import load_precomputation
from encctl_gym.crypto.group import get_group
from encctl_gym.errors import ConfigError, EncctlError, ResourceLimitError
from encctl_gym.plant_file import load_plant_file


def _member(shape: tuple[int, ...], descr: str = "<f8", data: bytes = b"\0" * 64) -> bytes:
    """An .npy member whose header declares ``shape`` but holds only ``data``."""
    buf = io.BytesIO()
    npy_format.write_array_header_1_0(buf, {"descr": descr, "fortran_order": False, "shape": shape})
    return buf.getvalue() + data


def _zip(path: Path, members: dict[str, bytes], compression: int = zipfile.ZIP_STORED) -> Path:
    with zipfile.ZipFile(path, "w", compression=compression) as zf:
        for name, raw in members.items():
            zf.writestr(f"{name}.npy", raw)
    return path


@pytest.fixture()
def address_space_cap():
    """Cap the address space at 4 GiB so an allocation of the declared shape fails fast (MemoryError)
    instead of the test passing by luck on a machine with swap."""
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = 4 << 30
    if hard != resource.RLIM_INFINITY and hard < cap:
        cap = hard
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    yield
    resource.setrlimit(resource.RLIMIT_AS, (soft, hard))


def test_a_plant_npz_declaring_a_huge_shape_is_refused_before_allocating(tmp_path: Path, address_space_cap) -> None:
    path = _zip(tmp_path / "p.npz", {"A": _member((10**6, 10**6)), "B": _member((1, 1), data=b"\0" * 8)})
    assert path.stat().st_size < 1000  # a few hundred bytes declaring 8e12 bytes
    with pytest.raises(ResourceLimitError, match=r"declared in system file .*p\.npz.*7\.\d+e\+03 GiB.*MAX_FILE_BYTES"):
        load_plant_file(path)


def test_design_on_a_huge_declared_shape_exits_2(tmp_path: Path, address_space_cap, capsys) -> None:
    path = _zip(tmp_path / "p.npz", {"A": _member((10**6, 10**6)), "B": _member((1, 1), data=b"\0" * 8)})
    assert main(["design", str(path)]) == 2
    assert "MAX_FILE_BYTES" in capsys.readouterr().err


def test_a_truncated_member_is_a_config_error(tmp_path: Path) -> None:
    path = _zip(tmp_path / "t.npz", {"A": _member((4, 4), data=b"\0" * 16), "B": _member((4, 1), data=b"\0" * 32)})
    with pytest.raises(ConfigError, match=r"t\.npz.*'A\.npy' is truncated: 16 bytes of data, its header declares 128"):
        load_plant_file(path)


def test_a_fortran_ordered_member_reads_as_numpy_reads_it(tmp_path: Path) -> None:
    A = np.asfortranarray(np.array([[0.5, 0.1, 0.0], [0.0, 0.4, 0.2]]))
    path = tmp_path / "f.npz"
    np.savez(path, A=A, x=np.arange(3, dtype=np.int32))
    got = read_npz(str(path), where="f", max_bytes=1 << 20, max_members=2, limit_name="X")
    np.testing.assert_array_equal(got["A"], A)
    np.testing.assert_array_equal(got["x"], [0, 1, 2])
    assert got["x"].dtype == np.int32


def test_a_flipped_byte_in_an_uncompressed_plant_npz_is_a_config_error(tmp_path: Path) -> None:
    ok = tmp_path / "ok.npz"
    np.savez(ok, A=0.5 * np.eye(2), B=np.ones((2, 1)))
    raw = bytearray(ok.read_bytes())
    with zipfile.ZipFile(ok) as zf:
        info = zf.getinfo("A.npy")
    raw[info.header_offset + 30 + len(info.filename) + 130] ^= 0xFF  # one byte of A's data
    bad = tmp_path / "flip.npz"
    bad.write_bytes(bytes(raw))
    with pytest.raises(ConfigError, match=r"flip\.npz.*not a readable NPZ archive.*CRC"):
        load_plant_file(bad)


def _overwrite_compressed(src: Path, dst: Path, member: str, count: int = 40) -> Path:
    raw = bytearray(src.read_bytes())
    with zipfile.ZipFile(src) as zf:
        info = zf.getinfo(member)
    start = info.header_offset + 30 + len(info.filename) + len(info.extra) + 8
    assert info.compress_type == zipfile.ZIP_DEFLATED and info.compress_size > start - info.header_offset + count
    raw[start : start + count] = b"\x17" * count
    dst.write_bytes(bytes(raw))
    return dst


def test_a_corrupt_compressed_plant_npz_is_a_config_error(tmp_path: Path) -> None:
    ok = tmp_path / "ok.npz"
    np.savez_compressed(ok, A=0.5 * np.eye(30), B=np.ones((30, 1)))
    bad = _overwrite_compressed(ok, tmp_path / "z.npz", "A.npy")
    with pytest.raises(ConfigError, match=r"z\.npz.*not a readable NPZ archive"):
        load_plant_file(bad)


@pytest.fixture(scope="module")
def saved(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("pre") / "ic40.npz"
    get_breaker("index-calculus", rng=3).precompute(get_group(40)).save(path)
    return path


def _with_member(src: Path, dst: Path, name: str, raw: bytes) -> Path:
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for info in zin.infolist():
            zout.writestr(info.filename, raw if info.filename == f"{name}.npy" else zin.read(info))
    return dst


def test_a_precomputation_declaring_a_huge_logs_shape_is_refused(saved: Path, tmp_path: Path, address_space_cap) -> None:
    bad = _with_member(saved, tmp_path / "huge.npz", "logs", _member((10**12, 8), descr="|u1"))
    with pytest.raises(ResourceLimitError, match=r"declared in the precomputation file .*huge\.npz.*MAX_FILE_BYTES"):
        load_precomputation(bad)


def test_crack_with_a_huge_declared_precomputation_exits_2(saved: Path, tmp_path: Path, address_space_cap, capsys) -> None:
    bad = _with_member(saved, tmp_path / "huge.npz", "logs", _member((10**12, 8), descr="|u1"))
    group = json.loads(str(np.load(saved)["header"][()]))["group"]
    bits = int(group["p"], 16).bit_length()
    assert main(["crack", "--bits", str(bits), "--keys", "1", "--load-precomputation", str(bad)]) == 2
    assert "MAX_FILE_BYTES" in capsys.readouterr().err


def test_a_corrupt_precomputation_archive_is_a_config_error(saved: Path, tmp_path: Path) -> None:
    names = zipfile.ZipFile(saved).namelist()
    member = max(names, key=lambda n: zipfile.ZipFile(saved).getinfo(n).compress_size)
    bad = _overwrite_compressed(saved, tmp_path / "z.npz", member)
    with pytest.raises(ConfigError, match=r"z\.npz.*not a readable NPZ archive"):
        load_precomputation(bad)
    with pytest.raises(EncctlError):
        load_precomputation(_with_member(saved, tmp_path / "o.npz", "logs", _member((2,), descr="|O")))
