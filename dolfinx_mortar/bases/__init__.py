"""The six mortar bases of the contact pressure (docs/DESIGN.md, §Bases)."""
