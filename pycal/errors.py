"""Errors that name the file and the field that is wrong."""


class PycalError(Exception):
    """Base class for every error pycal reports to the user (one clear line)."""


class ConfigError(PycalError):
    """A config or lab-data file is wrong: `file: field: reason`."""

    def __init__(self, file, field, reason):
        self.file, self.field, self.reason = str(file), str(field), str(reason)
        super().__init__(f"{self.file}: {self.field}: {self.reason}" if self.field
                         else f"{self.file}: {self.reason}")


class RunError(PycalError):
    """A YADE run failed (blew up, timed out, wrote no result)."""


class BudgetSpent(PycalError):
    """A study's run budget (max_runs_count) does not allow the runs asked for."""
