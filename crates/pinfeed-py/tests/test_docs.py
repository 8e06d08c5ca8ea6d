"""What README.md and docs/python.md show of the package is what it does today."""

import contextlib
import io
import re

import pytest

import pinfeed


def _blocks(text: str):
    """The fenced code blocks of a Markdown text: (language, body)."""
    return re.findall(r"^```(\w*)\n(.*?)^```$", text, flags=re.M | re.S)


def test_readme_python_example_prints_what_readme_says(root):
    readme = (root / "README.md").read_text()
    section = readme.split("\n## From Python\n")[1].split("\n## ")[0]
    blocks = _blocks(section)
    code = next(body for lang, body in blocks if lang == "python")
    shown = next(body for lang, body in blocks if lang == "text")
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, "README.md", "exec"), {})
    assert out.getvalue() == shown


def test_python_md_errors_are_the_packages(root):
    doc = (root / "docs" / "python.md").read_text()
    session = next(body for lang, body in _blocks(doc) if "PinfeedError:" in body)
    lines = session.splitlines()
    checked = 0
    for call, shown in zip(lines[::2], lines[1::2]):
        assert call.startswith(">>> ") and shown.startswith("pinfeed.PinfeedError: ")
        with pytest.raises(pinfeed.PinfeedError) as e:
            eval(call[4:], {"pinfeed": pinfeed})
        assert str(e.value) == shown[len("pinfeed.PinfeedError: "):]
        checked += 1
    assert checked == 2
