"""Penalty mortar contact as a term of the user's DOLFINx model.

Subpackages, one per concept (docs/DESIGN.md, §Architecture): each is used
from outside through its ``__init__`` only.

- :mod:`.gap_sources`: the gap-source interface and its implementations
  (frozen and current bases, obstacle and elastic master, GLS);
- :mod:`.laws`: the normal penalty law and Coulomb friction's law;
- :mod:`.friction`: the slip and history of Coulomb friction;
- :mod:`.obstacles`: the rigid-obstacle interface and the analytic obstacles;
- :mod:`.newton`: how the contact enters Newton;
- :mod:`.checks`: set-up and range checks;
- :mod:`.results`: pressures, forces, slip.

:class:`~dolfinx_mortar.contact.term.ContactTerm` (:mod:`.term`) puts them together.
"""
