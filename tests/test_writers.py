"""Writers check their destination first and leave nothing behind (issue 36, item 7).

A failure while writing (simulated: ``Path.write_text`` raising ENOSPC, a full
disk) leaves neither the file nor a temporary file, and the error names the
destination, not a hidden ``.tmp``. A destination under a file, or in a folder
where nothing can be created, is refused before any work.
"""

import errno
import os
from pathlib import Path

import pytest

from hinfnav.core.exceptions import InputError
from hinfnav.core.validation import check_new_file
from hinfnav.io.outputs import atomic_write_text, check_output_dir, write_json


def test_full_disk_leaves_no_temporary_file(tmp_path, monkeypatch):
    real = Path.write_text

    def full(self, *args, **kwargs):
        real(self, "")  # a 0-byte file, as a full disk leaves
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(Path, "write_text", full)
    with pytest.raises(OSError, match=r"cannot write .*summary\.json: No space left"):
        write_json(tmp_path / "summary.json", {"a": 1})
    assert list(tmp_path.iterdir()) == []


def test_interrupt_while_writing_leaves_nothing(tmp_path, monkeypatch):
    def interrupted(self, *args, **kwargs):
        Path.touch(self)
        raise KeyboardInterrupt

    monkeypatch.setattr(Path, "write_text", interrupted)
    with pytest.raises(KeyboardInterrupt):
        atomic_write_text(tmp_path / "x.txt", "data")
    assert list(tmp_path.iterdir()) == []


def test_destinations_refused_before_any_work(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(InputError, match="is a file"):
        check_output_dir(blocker / "out")
    with pytest.raises(InputError, match="does not exist"):
        check_new_file("--save", tmp_path / "missing" / "d.json")

    def refuse(*args, **kwargs):  # what a read-only file system answers, even to root
        raise OSError(errno.EROFS, os.strerror(errno.EROFS))

    monkeypatch.setattr("tempfile.mkstemp", refuse)
    with pytest.raises(InputError, match="cannot write in .*Read-only file system"):
        check_new_file("--save", tmp_path / "d.json")
    with pytest.raises(InputError, match="cannot write in .*Read-only file system"):
        check_output_dir(tmp_path / "new" / "out")


def test_worker_start_failure_is_one_line(monkeypatch):
    import distributed

    from hinfnav.campaign.runner import _open_client
    from hinfnav.core.exceptions import HinfnavError

    def dead(*args, **kwargs):
        try:
            raise OSError("worker process exited with code -9")
        except OSError as exc:
            raise RuntimeError("Nanny failed to start.") from exc

    monkeypatch.setattr(distributed, "LocalCluster", dead)
    with pytest.raises(HinfnavError, match=r"did not start .*Nanny failed to start.*exited with code -9") as info:
        _open_client(None, 2, 5.0)
    assert "\n" not in str(info.value)
