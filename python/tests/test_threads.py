"""The GIL is released while rendering, and Ctrl-C stops a render."""

import _thread
import signal
import threading

import numpy as np
import pytest

import glint
from conftest import cornell, counting_thread


def test_other_python_threads_run_while_rendering():
    s = cornell(64)
    glint.render(s, spp=1)  # build first: only the render itself is measured
    with counting_thread() as counter:
        start = counter[0]
        glint.render(s, spp=64)
        during = counter[0] - start
    # Were the GIL held, the counting thread could not run at all during the render.
    assert during > 10


def test_keyboard_interrupt_keeps_the_session_usable():
    session = glint.Session(cornell(64), spp=100000)
    # Python handles Ctrl-C only where the process did not start with SIGINT ignored, as a
    # background job of a script does (`cmd &`); there `interrupt_main` does nothing and the
    # render ran on. The test installs Python's handler, as an interactive session has it.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.5, _thread.interrupt_main)
    timer.start()
    try:
        # The time limit bounds the test should the interrupt still be lost; the render
        # must stop long before it.
        with pytest.raises(KeyboardInterrupt):
            session.render_passes(time_limit=60)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    done = session.spp
    assert 0 < done < 100000
    assert session.render_passes(2) == 2
    assert session.spp == done + 2
    assert np.isfinite(session.image()).all()
