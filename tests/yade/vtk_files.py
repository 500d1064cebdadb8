"""Reading YADE's VTK snapshots in the tests (no VTK library: the XML header is enough)."""
import re
from pathlib import Path


def vtu_header(path):
    """(points count, cells count, {array name: (RangeMin, RangeMax)}) of one .vtu file."""
    head = Path(path).read_bytes()[:6000].decode("latin-1")
    piece = re.search(r'<Piece NumberOfPoints="\s*(\d+)\s*"\s+NumberOfCells="\s*(\d+)', head)
    arrays = dict((m.group(1), (float(m.group(2)), float(m.group(3)))) for m in re.finditer(
        r'Name="(\w+)"[^>]*?RangeMin="\s*([-\d.e+]+)\s*"\s+RangeMax="\s*([-\d.e+]+)', head))
    return int(piece.group(1)), int(piece.group(2)), arrays
