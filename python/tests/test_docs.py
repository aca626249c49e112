"""Every code block of docs/python.md and of the README's Python tour runs as written
(from the repository root)."""

import os
import pathlib
import re
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_every_example_in_docs_python_md_runs():
    text = (ROOT / "docs" / "python.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 7
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        for i, code in enumerate(blocks):
            exec(compile(code, f"docs/python.md block {i + 1}", "exec"), {})
    finally:
        os.chdir(cwd)


def test_the_readme_python_tour_runs():
    # The README's blocks continue one another (the second uses `t` from the first),
    # so they share one namespace.
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 2
    # Run in a scratch folder (the tour writes files) with `scenes/` reachable.
    cwd = os.getcwd()
    with tempfile.TemporaryDirectory() as scratch:
        os.symlink(ROOT / "scenes", pathlib.Path(scratch) / "scenes")
        os.chdir(scratch)
        namespace = {}
        try:
            for i, code in enumerate(blocks):
                exec(compile(code, f"README.md python block {i + 1}", "exec"), namespace)
        finally:
            os.chdir(cwd)
