import pytest
from hypothesis import settings

from pushrecovery import BodyParams, load_params

settings.register_profile("ci", max_examples=40, deadline=None, derandomize=True)
settings.load_profile("ci")


@pytest.fixture
def params() -> BodyParams:
    return load_params()
