"""Gap sources with the bases on the current surfaces, exactly linearized."""
from dolfinx_mortar.contact.gap_sources.current.mortar import CurrentMortarGap
from dolfinx_mortar.contact.gap_sources.current.obstacle import CurrentObstacleGap

__all__ = ["CurrentMortarGap", "CurrentObstacleGap"]
