"""Slave and master surfaces: Lagrange facets, NURBS patches, DOLFINx facet meshtags."""
