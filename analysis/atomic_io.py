"""Result files whole or absent: each is written to a temporary file beside its target and renamed into
place, so an interrupted analysis leaves the previous file or the complete new one (docs/testing.md,
"Nothing half-written"). Shared by the scripts in analysis/."""
import os
import tempfile


def atomic_write(path, write):
    """Calls write(tmp) with a temporary path in the target's folder, then renames tmp to path."""
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=folder, suffix=os.path.splitext(path)[1])
    os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def write_text(path, text):
    def write(tmp):
        with open(tmp, "w") as f:
            f.write(text)
    atomic_write(path, write)


def emit(text, path=None):
    """A summary's Markdown: written whole to path when one is given, and printed."""
    if path:
        write_text(str(path), text)
    print(text)
