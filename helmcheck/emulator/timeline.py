"""The emulator core's clock: :class:`Timeline`, a mixin of :class:`~.core.EmulatorCore` that
brings the plant and the model to vehicle time and says when there is next something to do.

Vehicle time is ``time_scale × (now - start)`` (RH-TIM-2). Model timers, the mission's own
Maximum Operation Time (RH-SAF-5) and plant events run in time order; with a control tick
(:mod:`.freedoms`) the vehicle time reached is rounded down to a tick, timer deadlines up to one,
and plant events land on the next tick (RH-RD-15).
"""

from __future__ import annotations

import math
from typing import Optional

from .logs import event_text

__all__ = ["Timeline"]


class Timeline:
    """Vehicle time for :class:`~.core.EmulatorCore`: the clocks, catching up, the next wake-up."""

    def vehicle_time(self, now: float) -> float:
        """Vehicle seconds at wall time ``now`` (RH-TIM-2)."""
        return (now - self.start) * self.time_scale

    def wall_time(self, vehicle_t: float) -> float:
        return self.start + vehicle_t / self.time_scale

    def next_wakeup(self) -> Optional[float]:
        """Wall time of the next thing :meth:`tick` must do, or ``None`` (wait for input)."""
        best: Optional[float] = None
        up = self._tick_up
        md = self.model.next_deadline()
        if md is not None:
            best = self.wall_time(up(max(md, self.v)))
        rd = self.rules.due_v
        if rd is not None:
            w = self.wall_time(up(max(rd, self.v)))
            best = w if best is None else min(best, w)
        pb = self.plant.next_event_in(self.model)
        if pb is not None:
            w = self.wall_time(up(self.v + max(pb, self.plant.params.dt / 4)))
            best = w if best is None else min(best, w)
        if self._out:
            w = self.pacer.free_at
            best = w if best is None else min(best, w)
        if self._inbox:
            w = self._inbox[0][0]
            if self.settings.process_when_idle:  # it also waits for the line to be idle
                w = max(w, self.pacer.free_at)
            best = w if best is None else min(best, w)
        return best

    def _tick_up(self, v: float) -> float:
        """The first control tick at or after vehicle time ``v`` (``v`` itself with no tick)."""
        k = self.tick_v
        if not k:
            return v
        return max(v, math.ceil(v / k - 1e-9) * k)

    def _tick_down(self, v: float) -> float:
        k = self.tick_v
        if not k:
            return v
        return math.floor(v / k + 1e-9) * k

    def _catch_up(self, now: float) -> float:
        """Bring plant and model to vehicle time ``vehicle_time(now)``, events in time order."""
        target = self._tick_down(self.vehicle_time(now))
        if target < self.v:
            target = self.v
        m, p = self.model, self.plant
        up = self._tick_up
        for _ in range(100_000):  # a hard bound; each pass consumes time, an event or a timer
            md = m.next_deadline()
            if md is not None and self.tick_v:
                md = up(md)  # a timer takes effect on the control tick after it ran out
            if md is not None and md <= self.v:
                self._push_snapshot()
                wall = self.wall_time(self.v)
                for me in self._model_call(lambda: m.advance(self.v), wall) or ():
                    self._model_event(me, wall)
                p.sync(m)
                continue
            rd = self.rules.due_v
            if rd is not None and self.tick_v:
                rd = up(rd)
            if rd is not None and rd <= self.v:  # the mission's Maximum Operation Time tripped
                self._push_snapshot()
                wall = self.wall_time(self.v)
                ev = self.rules.fire()
                self.stats["faults"] += 1
                self._note(wall, f"plant: {event_text(ev)} at v={self.v:.3f}")
                for me in self._model_call(lambda: m.plant(ev, self.v), wall) or ():
                    self._model_event(me, wall)
                p.sync(m)
                continue
            seg_end = min(x for x in (target, md, rd) if x is not None)
            if self.v >= seg_end:
                break
            evs = p.step(m, seg_end - self.v)
            if not evs:
                self.v = seg_end
                continue
            self.v = min(seg_end, self.v + p.consumed)
            if self.tick_v:  # the control loop learns of it on its next tick
                tick_end = min(seg_end, up(self.v))
                while self.v < tick_end - 1e-12:
                    more = p.step(m, tick_end - self.v)
                    self.v = min(tick_end, self.v + p.consumed) if more else tick_end
                    evs += more
                self.v = tick_end
            self._push_snapshot()
            wall = self.wall_time(self.v)
            for e in evs:
                self._note(wall, f"plant: {event_text(e)} at v={self.v:.3f}")
                for me in self._model_call(lambda e=e: m.plant(e, self.v), wall) or ():
                    self._model_event(me, wall)
            p.sync(m)
        self._push_snapshot()
        return self.v

    def _push_snapshot(self) -> None:
        m = self.model
        if self._shaper.st.idle_distance == "last":
            target = m.navigation_target()
            if target is not None:
                self._last_target = target
        snap = self.plant.snapshot(m, self.v, self.utc0, m.snapshot)
        out = self._model_call(lambda: m.update_plant(snap), self.wall_time(self.v)) or ()
        for me in out:
            self._note(self.wall_time(self.v), f"model: {event_text(me)}")
