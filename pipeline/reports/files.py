"""The files of ``pipeline run``'s output folder as the run writes them: atomically (a temporary
file created exclusively in the same folder, then renamed), so an interrupted run never leaves a
half-written report; only files the run wrote are ever replaced or removed (:class:`Outputs`, and
the manifest that says which); the journals it keeps there (the manifest, the resume journal) are
appended a line at a time (:func:`append_line`).  The content depends only on the inputs (no time
stamps, fixed number formatting, input order), so re-running into the same folder gives identical
files.
"""
from __future__ import annotations

import contextlib
import hashlib
import os
import pathlib
import stat
import tempfile

from .cells import display
from .outfiles import MANIFEST

def write_atomic(path, data) -> pathlib.Path:
    """Write ``data`` (str or bytes) to ``path`` through a temporary file and a rename.

    The temporary file is created exclusively in ``path``'s folder (:func:`tempfile.mkstemp`: an
    unpredictable name, never opened through an existing symbolic link) and renamed over ``path``
    atomically (a symbolic link at ``path`` is replaced, its target left alone).  On any
    interruption the temporary file is removed and ``path`` keeps its previous content; Ctrl-C
    arriving during the write takes effect when the file is whole.  Unchanged files are not
    rewritten.
    """
    path = pathlib.Path(path)
    raw = data.encode("utf-8") if isinstance(data, str) else bytes(data)
    if _regular_file_bytes(path) == raw:
        return path
    return _replace(path, raw)


def _replace(path: pathlib.Path, raw: bytes) -> pathlib.Path:
    """:func:`write_atomic` once ``path`` is known not to hold ``raw`` already."""
    from .. import interrupts

    path.parent.mkdir(parents=True, exist_ok=True)
    with interrupts.deferred(), named_errors(path):
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name[:40]}.", suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as fh:
                os.fchmod(fh.fileno(), 0o666 & ~_umask())  # as an ordinary file, not mkstemp's 0600
                fh.write(raw)
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            raise
    return path


def _regular_file_bytes(path):
    """Content of ``path`` if it is a regular file (not through a symbolic link), else None."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
    except OSError:
        return None
    with os.fdopen(fd, "rb") as fh:
        if not stat.S_ISREG(os.fstat(fh.fileno()).st_mode):
            return None
        return fh.read()


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def remove_quietly(path) -> None:
    with contextlib.suppress(FileNotFoundError):
        pathlib.Path(path).unlink()


# -- what the tool wrote ---------------------------------------------------------------------------
_MANIFEST_HEADER = ("# pipeline run: the files it wrote into this folder (sha256 of the content, path); "
                    "it replaces or removes no other file\n")


class NotOurs(OSError):
    """A file in the output folder that ``pipeline run`` did not write (left as it is)."""


class Outputs:
    """The report files of one output folder, and the manifest that says which the tool wrote.

    A file is replaced or removed only when its present content is one the tool wrote there
    (recorded in :data:`MANIFEST` before the file is written, so that an interrupted run still
    knows its files); any other file in the way is left as it is (:class:`NotOurs`).
    """

    def __init__(self, folder):
        self.folder = pathlib.Path(folder)
        self.path = self.folder / MANIFEST
        self._written: dict[str, set[str]] = {}
        text = read_journal(self.path, _MANIFEST_HEADER)
        if text is not None:
            for line in text.splitlines()[1:]:
                digest, _, rel = line.partition("  ")
                if len(digest) == 64 and rel:
                    self._written.setdefault(rel, set()).add(digest)

    def _target(self, rel: str) -> pathlib.Path:
        return self.folder / rel

    def owned(self, rel: str) -> bool:
        """Whether the file at ``rel`` (a path relative to the folder) may be replaced: it does not
        exist, or its content is one the tool wrote there."""
        path = self._target(rel)
        if not os.path.lexists(path):
            return True
        raw = _regular_file_bytes(path)
        return raw is not None and _digest(raw) in self._written.get(rel, ())

    def check(self, rel: str) -> None:
        """Raise :class:`NotOurs` if the file at ``rel`` exists and was not written by the tool."""
        path = self._target(rel)
        if not self.owned(rel):
            raise NotOurs(f"{display(path)} exists and was not written by pipeline run "
                          f"(not in {MANIFEST}): left as it is")
        if not _real_folder(path.parent, self.folder):
            raise NotOurs(f"{display(path.parent)} is not a folder of its own (a symbolic link?): "
                          f"{path.name} not written")

    def write(self, rel: str, data) -> pathlib.Path:
        """Write ``data`` to ``rel`` atomically, unless a file the tool did not write is there."""
        raw = data.encode("utf-8") if isinstance(data, str) else bytes(data)
        path = self._target(rel)
        if _regular_file_bytes(path) == raw:
            return path  # already so (whoever wrote it, nothing changes)
        self.check(rel)
        digest = _digest(raw)
        if digest not in self._written.get(rel, ()):
            self._journal(f"{digest}  {rel}\n")
            self._written.setdefault(rel, set()).add(digest)
        return _replace(path, raw)

    def remove(self, rel: str) -> bool:
        """Remove the tool's file at ``rel``; True if removed, False if absent; :class:`NotOurs`
        for a file the tool did not write."""
        path = self._target(rel)
        if not os.path.lexists(path):
            return False
        self.check(rel)
        remove_quietly(path)
        return True

    def _journal(self, line: str) -> None:
        append_line(self.path, _MANIFEST_HEADER, line)

    def finish(self) -> None:
        """Rewrite the manifest compactly: for each file still there, the content the tool wrote
        (sorted, so that the same run gives the same manifest)."""
        lines = []
        for rel in sorted(self._written):
            path = self._target(rel)
            if not os.path.lexists(path):
                continue
            raw = _regular_file_bytes(path)
            digests = self._written[rel]
            if raw is not None and _digest(raw) in digests:
                digests = {_digest(raw)}
            lines += [f"{d}  {rel}\n" for d in sorted(digests)]
        if lines or os.path.lexists(self.path):
            write_atomic(self.path, _MANIFEST_HEADER + "".join(lines))


def read_journal(path, header: str) -> str | None:
    """The text of a journal this package keeps in an output folder (the manifest, the resume
    journal), or None when there is none yet.

    A file that is empty or holds only the start of ``header`` is what a run stopped by a full disk
    (or killed) while starting the journal leaves: it holds nothing, and counts as no journal.  Any
    other file that does not start with ``header`` was not written by ``pipeline run``:
    :class:`NotOurs`."""
    raw = _regular_file_bytes(path)
    if raw is None:
        if os.path.lexists(path):
            raise NotOurs(f"{display(path)} is not a file pipeline run wrote")
        return None
    text = raw.decode("utf-8", "replace")
    if header.startswith(text):  # empty, or the header cut short
        return None
    if not text.startswith(header):
        raise NotOurs(f"{display(path)} was not written by pipeline run")
    return text


def append_line(path, header: str, line: str) -> None:
    """Append ``line`` (ending in a newline) to the journal at ``path``, starting it with ``header``.

    A last line cut by a killed run is ended first, so that it spoils no other line; a journal
    holding only part of its header (see :func:`read_journal`) is started again.  Ctrl-C waits
    until the line is written.  A failure (a full disk ...) raises an :class:`OSError` naming the
    file."""
    from .. import interrupts

    head = header.encode("utf-8")
    with interrupts.deferred(), named_errors(path):
        flags = os.O_RDWR | os.O_APPEND | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0)
        fd = os.open(path, flags, 0o666)
        with os.fdopen(fd, "a+b") as fh:
            end = fh.seek(0, os.SEEK_END)
            if end < len(head):
                fh.seek(0)
                if head.startswith(fh.read()):  # nothing yet, or the header cut short
                    fh.truncate(0)
                    end = 0
            if end == 0:
                fh.write(head)
            else:
                fh.seek(end - 1)
                if fh.read(1) != b"\n":
                    fh.write(b"\n")
            fh.write(line.encode("utf-8"))


@contextlib.contextmanager
def named_errors(path):
    """Give an :class:`OSError` raised in the block the file's name where it has none (``No space
    left on device`` from a write says not which file)."""
    try:
        yield
    except OSError as exc:
        if exc.filename is not None or isinstance(exc, NotOurs):
            raise
        raise type(exc)(exc.errno, f"{exc.strerror or exc}", display(path)) from exc


def _digest(raw: bytes) -> str:
    return hashlib.sha256(raw).hexdigest()


def _real_folder(folder, top) -> bool:
    """Whether ``folder`` is ``top`` or inside it with no symbolic link or file on the way (folders
    not there yet are created as real ones)."""
    folder, top = pathlib.Path(folder), pathlib.Path(top)
    while folder != top:
        if folder.is_symlink() or (os.path.lexists(folder) and not folder.is_dir()):
            return False
        folder = folder.parent
    return True
