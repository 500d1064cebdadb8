"""The folder of the job being run, where every output goes (set by jobio.load_job; read
by jobio and vtk_output): the current directory if no job file was loaded (test scenes)."""
import os

_STATE = {"folder": None}


def set_folder(path):
    _STATE["folder"] = path


def get():
    return _STATE["folder"] or os.getcwd()
