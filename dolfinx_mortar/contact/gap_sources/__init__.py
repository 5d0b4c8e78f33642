"""Gap sources: where the nodal gaps d̄, their derivative G and the surface's
weights come from (docs/DESIGN.md, §Architecture).

Every source implements :class:`GapSource` and returns a
:class:`~dolfinx_mortar.contact.state.ContactState`;
the rest of the library asks a source only through that interface. Which
source a term's options mean is chosen in one place (:mod:`.choice`), and when
a source's bases are made again is its configuration's (:mod:`.configuration`).
"""
from dolfinx_mortar.contact.gap_sources.slip import SlipOperator, StepStart
from dolfinx_mortar.contact.gap_sources.source import GapSource, GlobalGapSource
from dolfinx_mortar.contact.gap_sources.configuration import configuration_of
from dolfinx_mortar.contact.gap_sources.current.mortar import FACET_SEARCH_FACTOR
from dolfinx_mortar.contact.gap_sources.choice import pairing_options

__all__ = ["FACET_SEARCH_FACTOR", "GapSource", "GlobalGapSource", "SlipOperator", "StepStart",
           "configuration_of", "pairing_options"]
