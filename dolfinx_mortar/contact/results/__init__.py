"""What a contact term reports: pressures, forces, slip and energies."""
from dolfinx_mortar.contact.results.contact_results import (ContactResults, SurfaceFriction,
                                                            SurfacePressure)

__all__ = ["ContactResults", "SurfaceFriction", "SurfacePressure"]
