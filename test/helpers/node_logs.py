"""What a node printed since a moment a test chose: a test that shares running nodes with others
checks only the lines its own actions caused, whatever ran before it."""
from __future__ import annotations


class LogMark:
    """The end of node ``name``'s log when the mark was made; :meth:`text` is what came after."""

    def __init__(self, suite, name: str):
        self.suite, self.name = suite, name
        self.offset = len(suite.log_text(name))

    def text(self) -> str:
        return self.suite.log_text(self.name)[self.offset:]
