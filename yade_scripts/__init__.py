"""What runs inside YADE: one script per rig (run as `yade -j1 -x -n yade_scripts/<rig>.py job.json`)
and the shared library `demlib`. The repo root must be on PYTHONPATH (the job runner sets it):
rig scripts import `yade_scripts.demlib` and `pycal` as packages.
"""
