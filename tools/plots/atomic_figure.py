"""A figure written whole or not at all, as the program writes its data (io::write_atomic):
matplotlib writes to a temporary name in the same folder (`<path>.tmp.<pid>`, so the format is
given explicitly, from the path's extension), the file is flushed to the disk, then renamed
over `path` (os.replace: atomic within a folder). A killed or failing script leaves the old
figure or none, never a truncated PNG/SVG; its temporary file is removed when it fails.
"""
import os


def savefig_atomic(fig, path, **kwargs):
    fmt = os.path.splitext(path)[1].lstrip(".").lower()
    tmp = f"{path}.tmp.{os.getpid()}"
    try:
        fig.savefig(tmp, format=fmt, **kwargs)
        with open(tmp, "rb") as f:
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.remove(tmp)
        except OSError:
            pass
        raise
