"""Error messages are one line, and memory checks respect the address space a process has left."""

from __future__ import annotations

import multiprocessing as mp
import resource
import sys

import numpy as np
import pytest

from encctl_gym._validation import as_finite_array, format_value
from encctl_gym.errors import ParameterError, ResourceLimitError
from encctl_gym.resources import MEMORY_LIMIT, check_memory, default_memory_limit, memory_headroom


def test_format_value_of_a_matrix_is_one_line():
    text = format_value(np.array([[1.0, 2.0], [3.0, 4.0]]))
    assert "\n" not in text and text == "array([[1., 2.], [3., 4.]], dtype=float64)"
    big = format_value(np.arange(100.0).reshape(10, 10))
    assert "\n" not in big and big.startswith("<array of shape (10, 10), dtype float64, first entries [0., 1.,")


def test_a_complex_matrix_error_names_it_on_one_line():
    with pytest.raises(ParameterError) as info:
        as_finite_array("Phi", np.array([[1 + 1j, 0], [0, 1]]))
    assert "Phi" in str(info.value) and "\n" not in str(info.value)


def test_check_memory_reports_estimates_beyond_the_float_range():
    with pytest.raises(ResourceLimitError, match=r"needs about 10\^400 bytes, above the limit of 8 GiB"):
        check_memory("a table of 10**400 entries", 10**400)


def test_without_an_address_space_limit_the_default_is_memory_limit():
    if resource.getrlimit(resource.RLIMIT_AS)[0] != resource.RLIM_INFINITY:
        pytest.skip("this process runs under an address-space limit")
    assert memory_headroom() is None and default_memory_limit() == MEMORY_LIMIT


def _capped(conn) -> None:  # pragma: no cover - runs in the child
    room_before = None
    try:
        vm = next(int(line.split()[1]) * 1024 for line in open("/proc/self/status") if line.startswith("VmSize:"))
        limit = vm + 256 * 2**20
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        room_before = memory_headroom()
        try:
            check_memory("a 1 GiB buffer", 2**30)
            conn.send((room_before, "no error"))
        except ResourceLimitError as exc:
            conn.send((room_before, str(exc)))
    except BaseException as exc:  # noqa: BLE001
        conn.send((room_before, f"{type(exc).__name__}: {exc}"))


@pytest.mark.skipif(sys.platform != "linux", reason="needs RLIMIT_AS and /proc")
def test_under_an_address_space_limit_check_memory_refuses_what_does_not_fit():
    ctx = mp.get_context("fork")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_capped, args=(child,))
    proc.start()
    room, message = parent.recv()
    proc.join()
    # the child capped itself at its mapped size + 256 MiB: about that much room is left
    assert room is not None and 0 < room <= 256 * 2**20
    assert "address space left" in message and "1 GiB" in message


@pytest.mark.parametrize("value", [bytearray(b"1"), b"12", memoryview(b"1"), "12"])
def test_bytes_and_text_are_not_read_as_numbers(value):
    with pytest.raises(ParameterError, match="A must be a numeric array"):
        as_finite_array("A", value)
