"""kernels.threads.one_thread: numba held at one thread in the block, restored after."""

import subprocess
import sys

import numba
import pytest

from pushrecovery.kernels.threads import one_thread


def test_one_thread_holds_numba_at_one_and_restores_the_count():
    before = numba.get_num_threads()
    with one_thread():
        assert numba.get_num_threads() == 1
    assert numba.get_num_threads() == before


def test_one_thread_restores_the_count_after_an_error():
    before = numba.get_num_threads()
    with pytest.raises(RuntimeError), one_thread():
        raise RuntimeError("a push failed")
    assert numba.get_num_threads() == before


def test_one_thread_does_not_load_numba():
    script = (
        "import sys\nfrom pushrecovery.kernels.threads import one_thread\n"
        "with one_thread():\n    pass\nprint('numba' in sys.modules)\n"
    )
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "False"
