"""Rigid analytic obstacles: the :class:`RigidObstacle` interface and the
plane, sphere and cylinder that implement it."""
from dolfinx_mortar.contact.obstacles.analytic import (RigidCylinder, RigidObstacle, RigidPlane,
                                                       RigidSphere, Translatable, relative_to)

__all__ = ["RigidCylinder", "RigidObstacle", "RigidPlane", "RigidSphere", "Translatable",
           "relative_to"]
