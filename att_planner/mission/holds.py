"""Holds, parks and recovery of the mission executive (decisions 3, 5 and 6 of
:mod:`att_planner.mission.executive`), without ROS.

:class:`Holds` is the part of :class:`~att_planner.mission.executive.MissionExecutive` that keeps the
spacecraft somewhere safe between slews: a hold in the controller's inertial pointing mode (asked
again while the controller refuses it after a ground site), a park at a source or a sky park
attitude that stays clear until a given time, the recovery of a held attitude from which no slew
can start, and the hold to the horizon once nothing is left to observe. It uses the executive's
request, report and wait primitives and its slew flight (``_fly``).
"""
from __future__ import annotations

from collections.abc import Callable

from att_msgs_py.types import MissionEventKind as Kind
from att_planner.mission import executive_io as io

PARKS_TRIED = 3                # nearest park sources tried per park
RECOVERY_STEP = 10.0           # s of sim time between the checks of a held attitude that cannot start a slew
RECOVERY_LIMIT = 1800.0        # s of sim time a mission waits for it at most
ESCAPE_LEAD = 60.0             # s of sim time from the request to the start of a slew away from a zone's path
ESCAPE_BUDGET = 2.0            # s of wall time the planner gets for it


class Holds:
    """Holds, parks and recovery (module docstring); mixed into the mission executive."""

    def _hold(self, name: str | None, then: Callable) -> None:
        """Hold still after reaching or leaving target ``name`` (None: where the day starts) in the
        controller's inertial pointing mode (the mode that dumps momentum): a source's attitude, else
        the attitude of that moment. After a site, whose pass can blind both star trackers (a mode
        starts on a converged estimate), the hold is asked again every :data:`RECOVERY_STEP` s, at
        most :data:`RECOVERY_LIMIT` s, while the controller refuses it. ``then`` the attitude held."""
        target = self._target(name) if name is not None else None
        fixed = target is not None and not target.moving
        q_BN = target.attitude if fixed else None
        t = self.t
        end = t + (RECOVERY_LIMIT if target is not None and target.moving else 0.0)
        asked, refusals = t, 0

        def answered(event):
            nonlocal refusals
            if not event.success:
                refusals += 1
                if refusals == 1:
                    self._log(t, f"the controller refused the hold {name or 'here'} (code {event.code}: "
                                 f"{event.message})" + (f": still tracking it, asking every {RECOVERY_STEP:g} s"
                                                        if end > t else ""))
                if asked < end:
                    return self._await_time(asked + RECOVERY_STEP, "holding", ask)
            then(target.attitude if fixed else self.q_BN)

        def ask(first: bool = False):
            nonlocal asked
            if not first:
                asked = self.t
            self._request(lambda number: io.SetPointing(number, q_BN), "holding", (io.PointingSet,), answered)
        ask(first=True)

    def _park(self, q_hold_BN, t: float, until: float, lead: float | None, budget: float | None,
              then: Callable) -> None:
        """Slew to a source that stays visible until ``until`` (:meth:`MissionScheduler.parks`, the
        nearest :data:`PARKS_TRIED`), starting ``lead`` s after ``t`` (default ``start_lead``), planned
        in ``budget``, and hold it; ``then`` (its attitude, the time after) or None when none was flown."""
        names = self.scheduler.parks(q_hold_BN, t, until)[:PARKS_TRIED]

        def attempt(i: int, t: float):
            if i == len(names):
                return then(None)
            name = names[i]

            def flown(end):
                if end is None:
                    return attempt(i + 1, self.t)
                self._report(Kind.PARK, name, end, max(end, until),
                             message=f"waiting at {name} until t = {until:.0f} s" if end < until else
                             f"parked at {name} after the t = {until:.0f} s it was to wait until: deciding again")
                self._hold(name, lambda q_BN: then((q_BN, end)))
            self._fly(name, q_hold_BN, t + (lead or self.start_lead), False, budget, flown)
        attempt(0, t)

    def _recover(self, q_hold_BN, t: float, until: float, then: Callable) -> None:
        """Get back to where a slew can start (:meth:`startable`): with a converged estimate a zone is
        about to cover the held attitude, so leave it while it is clear for :data:`ESCAPE_LEAD` s (a
        park planned in :data:`ESCAPE_BUDGET` s); else (or when no park was flown) hold until a slew
        can start, at most :data:`RECOVERY_LIMIT` s and not past ``until``. ``then`` (the attitude
        held, the time then)."""
        def hold_still():
            why = ("the estimate is not converged" if not self.converged else
                   "a zone reaches the held attitude, or no tracker sees the sky, within the lead")
            self._log(t, f"holding: {why}")
            check(t)

        end = min(t + RECOVERY_LIMIT, until)

        def check(t_now: float):
            if t_now < end and not self.startable(q_hold_BN, t_now):
                return self._await_time(t_now + RECOVERY_STEP, "recovering", lambda: check(self.t))
            then((q_hold_BN, t_now))

        if self.converged and self.scheduler.clear(q_hold_BN, t, t + ESCAPE_LEAD):
            self._log(t, "a zone is about to cover the held attitude: leaving it")
            return self._park(q_hold_BN, t, t + ESCAPE_LEAD + 2.0 * self.start_lead, ESCAPE_LEAD, ESCAPE_BUDGET,
                              lambda parked: then(parked) if parked is not None else hold_still())
        hold_still()

    def _hold_until(self, q_hold_BN, t: float, until: float, then: Callable) -> None:
        """With nothing left to observe, hold (dumping) until ``until`` (the horizon: the day is flown
        whole); a zone due at the held attitude within two leads is left for a park at a source clear
        for :data:`RECOVERY_LIMIT` s (or until ``until``), within one lead as :meth:`_recover` does
        (no slew follows: the trackers' view of the sky does not matter here)."""
        lead = self.start_lead

        def step(q_BN, t_now: float):
            self._await_time(min(until, t_now + RECOVERY_STEP), "holding", lambda: loop(q_BN, self.t))

        def loop(q_BN, t_now: float):
            if t_now >= until:
                return then()
            if self.scheduler.keeps_zones(q_BN, t_now, min(until, t_now + 2.0 * lead)):
                return step(q_BN, t_now)

            def parked(result):
                if result is not None:
                    return loop(*result)
                if not self.scheduler.keeps_zones(q_BN, t_now, min(until, t_now + lead)):
                    return self._recover(q_BN, t_now, until, lambda held: step(*held))
                step(q_BN, t_now)
            self._park(q_BN, t_now, min(until, t_now + RECOVERY_LIMIT), None, None, parked)
        loop(q_hold_BN, t)
