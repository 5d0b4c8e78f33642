"""Checks of a contact term: of its set-up (penalty, overlap, the obstacle's
side) and of the model's range during a solve (penetration, slip, the search
radius). Their warnings go to the logger ``dolfinx_mortar.contact.checks``."""
from dolfinx_mortar.contact.checks.range_checks import RangeChecks
from dolfinx_mortar.contact.checks.setup_checks import (check_initial_overlap,
                                                        check_penalty_against_stiffness,
                                                        check_penalty_represents_a_force,
                                                        warn_if_the_obstacle_faces_away)

__all__ = ["RangeChecks", "check_initial_overlap", "check_penalty_against_stiffness",
           "check_penalty_represents_a_force", "warn_if_the_obstacle_faces_away"]
