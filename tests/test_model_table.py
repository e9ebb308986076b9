"""The transition table: totality, agreement with the statechart, and the model following it.

``test_RH_ACK_4_every_mode_command_phase_follows_the_table`` is the exhaustive property test
over (mode × command × lockout phase): every pair either follows its table row or is rejected
with the row's error and no state change.
"""

from __future__ import annotations

import itertools
from types import SimpleNamespace

import pytest

from helmcheck.grammar import sentences as s
from helmcheck.model.chart import build_chart, chart_step
from helmcheck.model.plant import AtSurface, Submerged, WaypointReached
from helmcheck.model.testing import (catalog, odvl, ojw, ologd, ologl, omload, omp, oms, omstart,
                                     omstart_paper, omstop, omw, omw_clear, opk, opos, orwset, osd,
                                     oxflt, oxflt_profile)
from helmcheck.model.transitions import (ACK_TYPES, COMMAND_EVENTS, EVENTS, GUARD_ATOMS, MODES,
                                         PHASES, STAY, TABLE, rows_for, select)
from helmcheck.model.vehicle import VehicleModel


def test_table_every_command_has_a_deciding_row_in_every_state():
    for mode, phase, event in itertools.product(MODES, PHASES, COMMAND_EVENTS):
        rows = rows_for(mode, phase, event)
        assert rows, (mode, phase, event)
        assert rows[-1].guard == (), f"{mode}/{phase}/{event}: last row is guarded"


def test_table_rows_are_well_formed():
    for r in TABLE:
        assert r.event in EVENTS
        assert set(r.sources) <= set(MODES) and set(r.phases) <= set(PHASES)
        assert r.target == STAY or r.target in MODES
        assert r.phase_to is None or r.phase_to in PHASES
        assert r.clauses and all(c.startswith("RH-") for c in r.clauses)
        if r.error is not None:
            assert r.target == STAY and r.phase_to is None


def test_RH_SAF_1_lockout_rows_precede_everything_but_osd():
    for mode, event in itertools.product(MODES, COMMAND_EVENTS):
        first = rows_for(mode, "lockout", event)[0]
        assert (first.error == 26) == (event != "OSD")


def _ctx(values: dict) -> SimpleNamespace:
    ns = SimpleNamespace(**{a: False for a in GUARD_ATOMS})
    for k, v in values.items():
        setattr(ns, k, v)
    return ns


def test_chart_agrees_with_fast_dispatch_for_every_state_event_and_guard():
    chart = build_chart()()
    checked = 0
    for mode, phase, event in itertools.product(MODES, PHASES, EVENTS):
        rows = rows_for(mode, phase, event)
        atoms = sorted({a for r in rows for a, _ in r.checks})
        for bits in itertools.product((False, True), repeat=len(atoms)):
            ctx = _ctx(dict(zip(atoms, bits)))
            want = select(mode, phase, event, ctx)
            got = chart_step(chart, mode, phase, event, ctx)
            if want is None:
                assert (got.mode_row, got.safety_row) == (None, None)
                assert (got.mode, got.phase) == (mode, phase)
                continue
            assert got.mode_row == want.id and got.safety_row == want.id, (mode, phase, event, ctx)
            expect_mode = mode if want.error is not None or want.target == STAY else want.target
            expect_phase = phase if want.error is not None or want.phase_to is None else want.phase_to
            assert (got.mode, got.phase) == (expect_mode, expect_phase)
            checked += 1
    assert checked > 500


# ------------------------------------------------------------ the model follows the table


def _fresh():
    m = VehicleModel(oxflt_profile(), catalog())
    m.receive(ologl("a", "b"), 0.0)
    return m


def _started():
    m = _fresh()
    m.receive(omstart(srp="srp.mis"), 0.0)
    return m


def _do(m, *cmds):
    for c in cmds:
        if isinstance(c, (s.Command,)):
            m.receive(c, m.now or 0.0)
        else:
            m.plant(c, m.now or 0.0)
    return m


def _lockout(m, submerged=True):
    if submerged:
        m.plant(Submerged(6.0), m.now or 0.0)
    m.receive(oxflt("Sop"), m.now or 0.0)
    return m


def _ascent(m):
    _lockout(m)
    m.advance((m.now or 0.0) + 20.0)
    assert m.phase == "ascent"
    return m


def _parked():
    return _do(_started(), WaypointReached(), WaypointReached())


def _loaded():
    return _do(_fresh(), omload())


CONFIGS = {
    "S": _fresh, "S-loaded": _loaded, "N": _started, "P": _parked,
    "mP": lambda: _do(_started(), opk()), "A": lambda: _do(_started(), oms()),
    "M-idle": lambda: _do(_fresh(), omp()), "M-running": lambda: _do(_started(), omp()),
    "W": lambda: _do(_started(), omw(park_s=5), omw()),
    "lockout-S": lambda: _lockout(_fresh()), "lockout-N": lambda: _lockout(_started()),
    "lockout-P": lambda: _lockout(_parked()), "lockout-from-A": lambda: _lockout(_do(_started(), oms())),
    "ascent-S": lambda: _ascent(_fresh()), "ascent-N": lambda: _ascent(_started()),
    "ascent-P": lambda: _ascent(_parked()),
    "ascent-M-idle": lambda: _do(_ascent(_fresh()), omp()),
    "ascent-M-running": lambda: _do(_ascent(_started()), omp()),
    "surfaced-park": lambda: _do(_ascent(_started()), AtSurface()),
}

SAMPLES = {
    "OMS": oms(), "OMP": omp(), "OJW": ojw(1), "OPK": opk(), "OMW": omw(),
    "OMW_CLEAR": omw_clear(), "OMW_CLEAR_WP": omw_clear("CLEAR", omw()), "OMSTOP": omstop(),
    "OMLOAD": omload(), "OMSTART": omstart(), "OMSTART_PAPER": omstart_paper(), "OPOS": opos(),
    "OSD": osd("S"), "OLOGL": ologl("a"), "OLOGD": ologd("1"), "ORWSET": orwset("Sop"),
    "ODVL": odvl(),
}


def _event(name: str) -> str:
    return "OMSTART" if name == "OMSTART_PAPER" else name


def _fingerprint(m):
    return (m.state(), m.phase, m.mission_mode, m.mission_wp, m.loaded, m.servo, m.primitive,
            m.opk, tuple(m.queue), m.dvl, m.log_labels, len(m.log_rows), m.settings.as_dict(),
            m.timers.names(), m.snapshot, len(m.opos_records))


def test_every_config_is_reached():
    for name, make in CONFIGS.items():
        m = make()
        assert m.check_invariants() == [], name
    seen = {(make().mode, make().phase) for make in CONFIGS.values()}
    assert {m for m, _ in seen} == set(MODES)
    assert {p for _, p in seen} == set(PHASES)


@pytest.mark.parametrize("config", sorted(CONFIGS))
def test_RH_ACK_4_every_mode_command_phase_follows_the_table(config):
    for name, cmd in SAMPLES.items():
        m = CONFIGS[config]()
        mode, phase = m.mode, m.phase
        row = select(mode, phase, _event(name), m)
        before = _fingerprint(m)
        replies = m.receive(cmd, (m.now or 0.0) + 0.1)
        t = ACK_TYPES[_event(name)]
        last = replies[-1]
        assert isinstance(last, s.ACK) and last.type == t, (config, name, replies)
        if row.error is not None:
            assert replies == [s.ACK(t, 1, row.error)], (config, name)
            assert _fingerprint(m) == before, (config, name)
        elif last.status == 1:
            # a data check after the table (no mission loaded, index, look-up): no change
            assert last.err in (1, 3, 17, 19, 25, 31, 40), (config, name, last)
            assert _fingerprint(m) == before, (config, name)
        else:
            want_mode = mode if row.target == STAY else row.target
            want_phase = phase if row.phase_to is None else row.phase_to
            assert (m.mode, m.phase) == (want_mode, want_phase), (config, name, row)
            assert m.last_row is row
        assert m.check_invariants() == [], (config, name)
