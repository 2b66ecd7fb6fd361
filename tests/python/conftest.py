"""Shared fixtures of the Python module's tests (tests/python, run by ctest)."""
import os
import tempfile

import pytest

import caliper


@pytest.fixture(scope="session")
def model():
    return caliper.open_model("female")


@pytest.fixture(scope="session")
def regressors(model):
    return caliper.train_regressors(model)


@pytest.fixture()
def work():
    base = os.environ.get("CALIPER_PY_TEST_WORK")
    if base:
        os.makedirs(base, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=base) as d:
        yield d
