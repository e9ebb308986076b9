"""Faulty vehicles just past a range edge (:mod:`helmcheck.certify.vehicle.edges`): one per class
of edge that needs more than a field's value to reach — the distance of the ``$OPK`` limit, the
case of a keyword, the GPS fix of ``$OPOS`` — each caught by the case that reaches both sides of it
(V-67, V-69, V-70) on the clause that states the rule."""

from __future__ import annotations

from helmcheck.grammar import sentences as s
from helmcheck.model.handlers import ack

from .base import Model, Mutant

__all__ = ["MUTANTS"]


class OmwKeywordsCaseSensitive(Model):
    """RH-OMW-3, RH-RD-4: the ``$OMW`` keywords are matched as the profile spells them (``Clr``,
    ``CLEAR``, ``STOP``): ``clr``, ``Clear`` or ``stop`` is refused (36)."""

    def receive(self, item, now):
        if (isinstance(item, s.OMWClear) and item.keyword not in self.profile.omw_clear_keywords
                and self.phase == "none"):
            return [ack(16, 36)]
        return super().receive(item, now)


class OposAppliedInMission(Model):
    """RH-POS-2, RH-RD-10: while a mission runs the vehicle counts itself without a GPS fix even at
    the surface of a mission started normally, so an ``$OPOS`` position is applied there."""

    @property
    def gps_fix(self) -> bool:
        return super().gps_fix and self.mission is None


MUTANTS = (
    # 10 miles read as 16.6 km: an $OPK 16.17 km away is accepted (RH-RD-9: 16 093 m)
    Mutant("opk-limit-16.6-km", "RH-PK-1", ("RH-PK-1",), profile_changes=(("opk_max_distance_m", 16600.0),)),
    Mutant("omw-keywords-case-sensitive", "RH-OMW-3", ("RH-OMW-3",), model=OmwKeywordsCaseSensitive),
    Mutant("opos-applied-in-mission", "RH-POS-2", ("RH-POS-2",), model=OposAppliedInMission),
)
