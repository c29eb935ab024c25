"""The README stays short and true: at most 250 lines, its three quick starts are exactly the example
scripts that test/test_examples.py runs, each at most 20 lines, and every file it links to exists."""
from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
QUICK_STARTS = ("plan_and_verify.py", "fly_closed_loop.py", "suite_client.py")


def test_the_readme_is_at_most_250_lines():
    assert len(README.splitlines()) <= 250


def test_the_quick_starts_are_the_example_scripts():
    blocks = re.findall(r"```python\n(.*?)```", README, flags=re.S)
    assert blocks == [(ROOT / "examples" / name).read_text() for name in QUICK_STARTS]
    assert all(len(block.splitlines()) <= 20 for block in blocks)


def test_every_linked_file_exists():
    links = re.findall(r"\]\(([^)#]+)\)", README)
    assert links, "the README links to its documentation"
    missing = [link for link in links if not link.startswith("http") and not (ROOT / link).exists()]
    assert not missing, missing
