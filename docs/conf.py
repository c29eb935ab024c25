"""Sphinx configuration: MyST Markdown pages, and the reference pages generated from the code by the
``att_docs`` extension (``docs/_ext``) into ``docs/_generated`` at every build."""
from __future__ import annotations

import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path[:0] = [str(DOCS.parent), str(DOCS / "_ext")]      # this checkout's packages, then the extension

project = "att_suite"
author = "att_suite contributors"
copyright = "att_suite contributors, Apache License 2.0"

extensions = ["myst_parser", "att_docs"]
source_suffix = {".md": "markdown"}
root_doc = "index"
# _generated holds the files the pages include, never pages of their own
exclude_patterns = ["_build", "_generated", "_ext"]
myst_enable_extensions = ["dollarmath", "deflist"]
myst_heading_anchors = 3
# values, ranges and command lines are shown as typed: no curly quotes, no dashes for "--"
smartquotes = False
html_theme = "alabaster"
html_title = "att_suite"
