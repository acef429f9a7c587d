import os

import pytest
from hypothesis import settings

from pushrecovery import BodyParams, load_params

settings.register_profile("ci", max_examples=40, deadline=None, derandomize=True)
# make fuzz: the same properties with 50 times the examples, still derandomized (reproducible).
settings.register_profile("fuzz", max_examples=2000, deadline=None, derandomize=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


@pytest.fixture
def params() -> BodyParams:
    return load_params()


#: ``python *AS_FROM_A_TERMINAL ARGS`` runs ``pushrecovery ARGS`` with SIGINT at Python's
#: default, as a shell on a terminal starts a command. A test worker's own disposition is not
#: inherited: under a full pytest-xdist run a worker intermittently had SIGINT ignored (a
#: child started then reported SIG_IGN), and its children then could not be Ctrl-C'ed at all.
AS_FROM_A_TERMINAL = (
    "-c",
    "import runpy, signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
    "sys.argv[0] = 'pushrecovery'; runpy.run_module('pushrecovery', run_name='__main__')",
)


def cli_error(capsys: pytest.CaptureFixture[str], *args: str) -> str:
    """Run ``pushrecovery ARGS``; check it is refused in one line with exit 2; return the line."""
    from pushrecovery.cli import main

    with pytest.raises(SystemExit) as info:
        main(list(args))
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("pushrecovery: error: ") and err.count("\n") == 1, err
    return err
