import os
import signal
import time

import pytest

from seminspect.core.interrupts import (
    Interrupted,
    as_interrupted,
    deferred_signals,
    stop_on_signals,
)


@pytest.mark.parametrize(("signum", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_stop_signal_raises_interrupted_with_the_shells_exit_code(signum, code) -> None:
    previous = signal.getsignal(signum)
    with pytest.raises(Interrupted) as caught, stop_on_signals():
        os.kill(os.getpid(), signum)
    assert caught.value.signum == signum and caught.value.exit_code == code
    assert isinstance(caught.value, KeyboardInterrupt)
    assert signal.getsignal(signum) is previous  # handlers restored


def test_a_signal_during_a_deferred_block_arrives_after_it() -> None:
    finished = []
    with pytest.raises(Interrupted) as caught, stop_on_signals(), deferred_signals():
        os.kill(os.getpid(), signal.SIGTERM)
        finished.append("last status written")
    assert finished == ["last status written"] and caught.value.signum == signal.SIGTERM
    assert "SIGTERM" in caught.value.describe()


def test_a_signal_while_numba_compiles_is_raised_once_compilation_ends():
    import time

    from numba.core.compiler_lock import global_compiler_lock

    reached = []
    with stop_on_signals(), pytest.raises(Interrupted) as stopped:
        with global_compiler_lock:
            os.kill(os.getpid(), signal.SIGTERM)
            for _ in range(20):  # the handler runs here and must not raise
                time.sleep(0.01)
            reached.append("end of compilation")
        for _ in range(300):  # delivered again shortly after
            time.sleep(0.01)
    assert reached == ["end of compilation"]
    assert stopped.value.signum == signal.SIGTERM


def test_a_signal_while_a_kernel_calls_back_into_numba_is_raised_when_it_returns():
    """Boxing a kernel's tuple of arrays runs numba's Python code, which drops an exception
    raised there (the call then fails with ``SystemError``); the stop must wait for our code."""
    import sys
    import threading
    import time

    import numba
    import numpy as np

    @numba.njit
    def ramp(n):
        values = np.empty(n)
        for i in range(n):
            values[i] = i * 0.5
        return values, values[::2]

    ramp(3)
    for _ in range(10):  # raising at once failed nearly every time
        kill = threading.Timer(0.003, os.kill, (os.getpid(), signal.SIGTERM))
        deadline = time.monotonic() + 5  # before the timer: the signal may land at once
        with stop_on_signals(), pytest.raises(Interrupted) as stopped:
            kill.start()
            while time.monotonic() < deadline:
                ramp(200_000)
        kill.join()
        assert stopped.value.signum == signal.SIGTERM and time.monotonic() < deadline
        assert sys.getprofile() is None


def test_a_library_that_swaps_a_sigterm_for_its_own_keyboard_interrupt_still_reads_sigterm() -> (
    None
):
    # Ray catches the Interrupted of a signal during ray.wait and raises a bare KeyboardInterrupt
    with stop_on_signals():
        try:
            try:
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(5)  # the handler raises here
            except Interrupted:
                raise KeyboardInterrupt from None
        except KeyboardInterrupt as exc:
            stop = as_interrupted(exc)
    assert (stop.signum, stop.exit_code, stop.describe()) == (
        signal.SIGTERM,
        143,
        "stopped by SIGTERM",
    )
    assert as_interrupted(KeyboardInterrupt()).signum == signal.SIGINT  # outside: a Ctrl-C
