"""Shared library of the YADE rig scripts (runs inside YADE only).

jobio     - read the job file, write result.json/CSV atomically with provenance
(others)  - scene building: materials and contact laws, rig geometry, fills, measurements
"""
