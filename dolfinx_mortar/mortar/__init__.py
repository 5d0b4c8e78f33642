"""Slave–master segmentation and the mortar operators D, M and the raw gaps."""
