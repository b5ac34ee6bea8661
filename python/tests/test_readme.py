# SPDX-License-Identifier: BSD-3-Clause
"""README.md's "From Python" example runs as written, from the repository root, and prints what its
comments say it prints: a changed answer fails here until the README follows (its C++ twin is
PcdCollisionTool.TheDemoAnswersTheDocsQuote)."""
import contextlib
import io
import os
import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[2]


def readme_python_example():
    """The first ```python block after the README's "## From Python" heading."""
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## From Python"):]
    match = re.search(r"```python\n(.*?)```", section, re.S)
    assert match, "README.md has no python block under '## From Python'"
    return match.group(1)


def test_the_readme_python_example_prints_what_it_says():
    code = readme_python_example()
    # Each print(...) line's comment is what it prints, "..." standing for what the comment leaves out.
    promised = [line.split("#", 1)[1].strip() for line in code.splitlines()
                if line.startswith("print(") and "#" in line]
    assert promised, "the example's print lines say nothing of what they print"
    out = io.StringIO()
    cwd = os.getcwd()
    os.chdir(ROOT)  # its paths are the repository's, as the README runs it
    try:
        with contextlib.redirect_stdout(out):
            scope = {}
            exec(compile(code, "README.md (From Python)", "exec"), scope)
    finally:
        os.chdir(cwd)
    printed = out.getvalue().splitlines()
    assert len(printed) == len(promised), printed
    for line, comment in zip(printed, promised):
        pattern = ".*".join(re.escape(part) for part in comment.split("..."))
        assert re.fullmatch(pattern, line), (line, comment)
    # The batch below the print ran over every pose and answered each.
    assert len(scope["probabilities"]) == 1000
    assert all(0.0 <= p <= 1.0 for p in scope["probabilities"])
