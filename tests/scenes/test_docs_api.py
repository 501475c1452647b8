"""The examples of docs/api.md: every ```python block runs (in order, in one namespace per
block, as a user's script would) and checks its own result with asserts."""

import re
import runpy
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[2] / "docs" / "api.md"
FENCE = re.compile(r"^```python\n(.*?)^```$", re.MULTILINE | re.DOTALL)


def _blocks():
    text = DOC.read_text(encoding="utf-8")
    return [
        pytest.param(m.group(1), id=f"line{text.count(chr(10), 0, m.start()) + 1}")
        for m in FENCE.finditer(text)
    ]


def test_document_has_examples():
    assert len(_blocks()) >= 2


@pytest.mark.parametrize("code", _blocks())
def test_python_block_runs(code, capsys, tmp_path):
    script = tmp_path / "example.py"
    script.write_text(code, encoding="utf-8")
    runpy.run_path(str(script), run_name="__main__")
    assert capsys.readouterr().out.strip()  # each example prints what it found
