"""What a rig run and pycal agree on (one place, imported by pycal and by yade_scripts).

A job folder holds JOB_FILE (the resolved job) and, once the run succeeded,
RESULT_FILE (written last, atomically). When the rig itself refuses the run (no rest,
blow-up: a RigFailure) it writes RIG_FAILURE_FILE instead and exits with
EXIT_RIG_FAILURE; any other error exits with EXIT_ERROR. YADE's output goes to LOG_FILE.
"""

JOB_FILE = "job.json"
RESULT_FILE = "result.json"
RIG_FAILURE_FILE = "rig_failure.txt"
LOG_FILE = "yade.log"

EXIT_OK = 0
EXIT_RIG_FAILURE = 3        # the rig refused the run: same job and seed fail the same way (kept as a verdict)
EXIT_ERROR = 4              # a bug or a crash: not a verdict, the job runs again
