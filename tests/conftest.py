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
