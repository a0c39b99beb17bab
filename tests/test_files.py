"""Reading input and writing output safely (pianobot/files.py): one clear line for every file
that cannot be read or written, and a failed write never changes an existing file."""

import errno
import os

import pytest
from conftest import fail_in, within

from pianobot import files
from pianobot.errors import PianobotError
from pianobot.files import atomic_write, check_writable, read_input


def test_only_regular_files_are_read_and_never_more_than_the_limit(tmp_path):
    (tmp_path / "small").write_bytes(b"x" * 10)
    assert read_input(tmp_path / "small", limit=10, kind="file") == b"x" * 10
    with pytest.raises(PianobotError, match="larger than"):
        read_input(tmp_path / "small", limit=9, kind="file")
    os.mkfifo(tmp_path / "fifo")
    (tmp_path / "loop").symlink_to(tmp_path / "loop2")
    (tmp_path / "loop2").symlink_to(tmp_path / "loop")
    (tmp_path / "dangling").symlink_to(tmp_path / "nowhere")
    with within(10):
        for path, words in (
            ("/dev/zero", "not a regular file"),  # st_size 0, and it never ends
            (tmp_path / "fifo", "not a regular file"),  # st_size 0, and a read waits for a writer
            (tmp_path / "loop", "loop of symbolic links"),
            (tmp_path / "dangling", "symbolic link to a file that does not exist"),
            (tmp_path / "missing", "no such file"),
            (tmp_path, "is a folder"),
        ):
            with pytest.raises(PianobotError, match=words):
                read_input(path, limit=1000, kind=".mid file")


@pytest.mark.parametrize(
    "error, words",
    [
        (errno.EROFS, r"read-only file system\): choose another folder"),
        (errno.EACCES, r"permission denied\): choose another folder"),
        (errno.ENOSPC, r"no space left on the device\): free some space"),
    ],
)
def test_check_writable_really_tries_the_folder(tmp_path, monkeypatch, error, words):
    monkeypatch.setattr(files.tempfile, "mkstemp", fail_in(tmp_path, error))
    with pytest.raises(PianobotError, match=words):
        check_writable(tmp_path / "out.mid")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_check_writable_refuses_a_read_only_folder(tmp_path):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o555)
    try:
        with pytest.raises(PianobotError, match="permission denied"):
            check_writable(folder / "out.mid")
    finally:
        folder.chmod(0o755)


def test_check_writable_leaves_nothing_behind_and_refuses_devices(tmp_path):
    assert check_writable(tmp_path / ("x" * 250 + ".mid")) == tmp_path / ("x" * 250 + ".mid")  # long names fit
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(PianobotError, match="not a regular file"):
        check_writable("/dev/null")  # the rename would replace the device itself


def test_a_failed_write_is_one_line_and_keeps_the_old_file(tmp_path, monkeypatch):
    target = tmp_path / "keep.json"
    target.write_text("precious")

    def full(fd):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(files.os, "fsync", full)
    with pytest.raises(PianobotError, match="could not write .*keep.json \\(no space left on the device\\)") as e:
        atomic_write(target, "new")
    assert "existing file is unchanged" in str(e.value) and "\n" not in str(e.value)
    with pytest.raises(PianobotError, match="nothing was written"):
        atomic_write(tmp_path / "new.json", "new")
    assert target.read_text() == "precious"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.json"]  # no temporary file left
