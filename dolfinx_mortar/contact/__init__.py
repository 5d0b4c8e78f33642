"""Gap models, rigid obstacles and the contact term added to a DOLFINx model."""
