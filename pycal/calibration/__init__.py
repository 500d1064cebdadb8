"""Calibration stages: each moves one parameter group until a rig response matches
its lab target (density from the cell fill, 1-D monotone solver for the rest)."""
