"""A calibrated set for other DEM codes: conversions (conversions.py, one function per
convention, pure maths) and the writers of each format (formats.py)."""
