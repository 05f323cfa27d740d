"""README's Python example runs as written and prints what its comments say."""

import contextlib
import io
import os
import re

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "..", ".."))


def test_readme_example_runs_as_written():
    text = open(os.path.join(ROOT, "README.md"), encoding="utf-8").read()
    section = text.split("## Python: exact ray queries on NumPy arrays", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    assert len(code.strip().splitlines()) <= 10
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, "README.md", "exec"), {})
    printed = out.getvalue().splitlines()
    promised = [line.split("# ", 1)[1].split(":")[0].strip() for line in code.splitlines() if line.startswith("print(")]
    assert len(printed) == len(promised) == 3
    for got, want in zip(printed, promised):
        assert got.split() == want.split(), (got, want)
