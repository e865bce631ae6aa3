"""An interrupt that lands in a ctypes callback (numba's LLVM compiling calls back into Python)
is swallowed there ("Exception ignored on calling ctypes callback"); the command must still stop
with exit 130, not run on as if never interrupted."""

import ctypes
import signal
import time

import pytest

from fricid.cli import _app

#: Signals sent at set moments: run alone, after the parallel tests (Makefile).
pytestmark = pytest.mark.serial


def _swallowed_interrupt() -> None:
    def callback() -> None:
        _app._State.signal = signal.SIGINT  # as the SIGINT handler records it
        raise KeyboardInterrupt

    ctypes.CFUNCTYPE(None)(callback)()  # the exception cannot cross C: ctypes drops it


def test_a_swallowed_interrupt_is_raised_again(capsys):
    with pytest.raises(KeyboardInterrupt), _app.signal_handlers():
        _swallowed_interrupt()
        deadline = time.monotonic() + 5.0
        while time.monotonic() < deadline:  # the command going on after the callback
            time.sleep(0.01)
    assert "Exception ignored" not in capsys.readouterr().err
