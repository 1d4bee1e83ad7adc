"""Bounded reading of NPZ archives (plant files, precomputation files).

An NPZ archive is a zip of ``.npy`` members; each member's header declares a dtype and a shape,
and ``numpy.load`` allocates ``prod(shape) * itemsize`` bytes before it reads the data. A
200-byte member declaring the shape (10^6, 10^6) thus asks for 7.3 TiB, whatever the zip says
of its size. :func:`read_npz` reads every member's header first
(``numpy.lib.format.read_magic`` / ``read_array_header_1_0`` / ``read_array_header_2_0``),
refuses object dtypes (pickles) and a declared total above the caller's bound, and only then
reads the data, exactly the declared number of bytes. A corrupt archive (a bad CRC, a broken
deflate stream, a truncated member) is one :class:`~encctl_gym.errors.ConfigError`, never a raw
``zlib.error`` or ``zipfile.BadZipFile``.
"""

from __future__ import annotations

import io
import math
import zipfile
import zlib
from typing import IO, Any, cast

import numpy as np
from numpy.lib import format as npy_format

from ._validation import format_value
from .errors import ConfigError, EncctlError
from .resources import check_memory

__all__ = ["read_npz"]

_ERRORS = (zipfile.BadZipFile, zlib.error, OSError, EOFError, ValueError, KeyError, TypeError, OverflowError)


def _header(member: IO[bytes], name: str, where: str) -> tuple[tuple[int, ...], bool, np.dtype[Any]]:
    """The shape, Fortran order and dtype a member declares (its data not read)."""
    version = npy_format.read_magic(member)
    if version == (1, 0):
        shape, fortran, dtype = npy_format.read_array_header_1_0(member)
    elif version == (2, 0):
        shape, fortran, dtype = npy_format.read_array_header_2_0(member)
    else:
        raise ConfigError(f"{where}: member {name!r} has npy format version {version}; this reader takes 1.0 and 2.0")
    if dtype.hasobject:
        raise ConfigError(f"{where}: member {name!r} holds Python objects (dtype {dtype}); it cannot be read without pickles")
    return tuple(int(s) for s in shape), bool(fortran), dtype


def read_npz(
    source: str | bytes, *, where: str, max_bytes: int, max_members: int, limit_name: str, members: set[str] | None = None
) -> dict[str, np.ndarray]:
    """Read the arrays of an NPZ archive within ``max_bytes``, without pickles.

    Parameters
    ----------
    source : str or bytes
        A path, or the archive's bytes.
    where : str
        What the archive is, for messages (``"system file 'p.npz'"``).
    max_bytes : int
        Largest total of the arrays' declared sizes (``prod(shape) * itemsize``) and of the
        members' uncompressed sizes, checked before any array is allocated.
    max_members : int
        Largest number of members.
    limit_name : str
        The name of the bound, for messages (``"MAX_FILE_BYTES"``).
    members : set of str, optional
        The member names (without ``.npy``) the archive must hold exactly.

    Returns
    -------
    dict
        The arrays by member name (without ``.npy``).

    Raises
    ------
    ConfigError
        If the archive is corrupt or truncated, has too many members, a member that is not an
        ``.npy`` array, other members than ``members``, or an object (pickled) array; the
        message names the archive.
    ResourceLimitError
        If the declared or uncompressed sizes exceed ``max_bytes`` (before allocating).
    """
    try:
        with zipfile.ZipFile(io.BytesIO(source) if isinstance(source, bytes) else source) as zf:
            infos = zf.infolist()
            if len(infos) > max_members:
                raise ConfigError(f"{where}: holds {len(infos)} arrays; at most {max_members} are read")
            names = {i.filename.removesuffix(".npy") for i in infos}
            if members is not None and names != members:
                raise ConfigError(f"{where}: holds {sorted(names)}, expected {sorted(members)}")
            check_memory(
                f"the uncompressed members of {where}", sum(i.file_size for i in infos), max_bytes, f"{limit_name} bounds them"
            )
            headers = []
            for info in infos:
                with zf.open(info) as member:
                    headers.append(_header(member, info.filename, where))
            declared = sum(math.prod(shape) * dtype.itemsize for shape, _, dtype in headers)
            check_memory(
                f"the arrays declared in {where} (shapes times itemsizes)", declared, max_bytes, f"{limit_name} bounds them"
            )
            arrays: dict[str, np.ndarray] = {}
            for info, (shape, fortran, dtype) in zip(infos, headers):
                arrays[info.filename.removesuffix(".npy")] = _data(zf, info, shape, fortran, dtype, where)
            return arrays
    except EncctlError:
        raise
    except _ERRORS as exc:
        text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ConfigError(f"{where}: not a readable NPZ archive ({format_value(text)})") from None


def _data(
    zf: zipfile.ZipFile, info: zipfile.ZipInfo, shape: tuple[int, ...], fortran: bool, dtype: np.dtype[Any], where: str
) -> np.ndarray:
    """A member's array: exactly its declared bytes after the header (the member read to its end, so
    the zip's CRC is checked)."""
    count = math.prod(shape)
    array = np.empty(count, dtype=dtype)
    with zf.open(info) as member:
        _header(member, info.filename, where)
        got = cast(io.BufferedIOBase, member).readinto(array.view(np.uint8).data) if array.nbytes else 0
        if got != array.nbytes:
            raise ConfigError(
                f"{where}: member {info.filename!r} is truncated: {got} bytes of data, its header declares {array.nbytes}"
            )
        member.read()  # to the end: a damaged member fails its CRC here
    return array.reshape(shape[::-1]).transpose() if fortran else array.reshape(shape)
