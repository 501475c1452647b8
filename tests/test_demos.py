"""The demos are literate scripts; each ends by checking a published or exact value."""

import runpy
from pathlib import Path

import pytest

DEMOS = sorted((Path(__file__).parent.parent / "demos").glob("*.py"))


@pytest.mark.parametrize("demo", DEMOS, ids=[d.stem for d in DEMOS])
def test_demo_runs_and_checks_its_result(demo):
    runpy.run_path(str(demo), run_name="__main__")
