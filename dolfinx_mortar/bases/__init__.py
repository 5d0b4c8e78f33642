"""The six mortar bases of the contact pressure (DESIGN.md §2)."""
