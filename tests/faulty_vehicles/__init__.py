"""Faulty vehicles for the certifier's self-test: the reference emulator with one fault each.

Every vehicle clause (§1–8) has at least one mutant its case catches on that clause, each
certified at two time scales (:data:`~.base.TIME_SCALES`). The toolkit is :mod:`.base`; the
mutants are in one module per family of clauses (:mod:`.wire`, :mod:`.control`) and one for the
range edges (:mod:`.edges`), and one for the rules only the traceability table's cases (V-80..V-89) reach
(:mod:`.rules`). They live in the tests, not the product: the product's emulator stays conforming.
"""

from . import control, edges, rules, wire
from .base import EMU_PROFILE, TIME_SCALES, Mutant, make_core, serve

__all__ = ["Mutant", "MUTANTS", "serve", "make_core", "EMU_PROFILE", "TIME_SCALES"]

MUTANTS: tuple[Mutant, ...] = wire.MUTANTS + control.MUTANTS + edges.MUTANTS + rules.MUTANTS
