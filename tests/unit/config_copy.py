"""Editing a copied config file in a test (the `cfg` fixture of conftest.py gives the copy)."""


def edit(path, old, new):
    """Replace the first `old` in the file by `new`; `old` must be there."""
    text = path.read_text()
    assert old in text, f"{old!r} not in {path}"
    path.write_text(text.replace(old, new, 1))
