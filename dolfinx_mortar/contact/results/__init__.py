"""What a contact term reports: pressures, forces, slip and energies."""
from dolfinx_mortar.contact.results.contact_results import ContactResults, SurfacePressure
from dolfinx_mortar.contact.results.friction_results import SurfaceFriction

__all__ = ["ContactResults", "SurfaceFriction", "SurfacePressure"]
