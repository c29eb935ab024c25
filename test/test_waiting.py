"""helpers.waiting: returns on the condition, fails by name at the deadline."""
import time

import pytest

from helpers.waiting import wait_until


def test_returns_as_soon_as_the_condition_holds():
    ready_at = time.monotonic() + 0.2
    start = time.monotonic()
    wait_until(lambda: time.monotonic() >= ready_at, 10.0, "the clock passed 0.2 s")
    assert 0.2 <= time.monotonic() - start < 2.0


def test_fails_with_what_it_waited_for_at_the_deadline():
    start = time.monotonic()
    with pytest.raises(pytest.fail.Exception, match=r"the impossible: not within 0.3 s"):
        wait_until(lambda: False, 0.3, "the impossible")
    assert 0.3 <= time.monotonic() - start < 2.0
