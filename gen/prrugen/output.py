"""Writing generated files so that a failure never leaves a half-written or
mixed set behind: every file goes to a temporary name in its directory
first, and only when all are written are they renamed into place."""

import os
import tempfile


def write_files_atomically(out_dir, files):
    """files: name -> text. Creates out_dir if missing."""
    os.makedirs(out_dir, exist_ok=True)
    staged = []
    try:
        for name, text in sorted(files.items()):
            fd, tmp = tempfile.mkstemp(prefix="." + name + ".", dir=out_dir)
            staged.append((tmp, os.path.join(out_dir, name)))
            with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as f:
                f.write(text)
            os.chmod(tmp, 0o644)
    except BaseException:
        for tmp, _ in staged:
            if os.path.exists(tmp):
                os.unlink(tmp)
        raise
    for tmp, final in staged:
        os.replace(tmp, final)
