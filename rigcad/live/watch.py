"""The watch loop: the profile's files (its ``extends:`` chain, the printer files given) watched
with ``watchfiles`` (Rust notify), each burst of writes debounced into one rebuild, every frame
pushed to the live view's :class:`rigcad.live.server.Hub` (and to an OCP CAD Viewer, and the
exports, when asked) and summed up in one terminal line.

The folders holding the files are watched, not the files: an editor that saves by writing a new
file and renaming it over the old one (vim, most IDEs) replaces the inode a file watch would hold.
Only events on the profile's own files count. The profile's own path is watched as named, links not
followed: a link renamed over it is read as data (its target too is then watched), and the real
file renamed back is seen. When an edit changes the ``extends:`` chain the
watch restarts on the new set of files.
"""

from __future__ import annotations

import time
from pathlib import Path

from rigcad.errors import ProfileError, one_line

#: Longest a burst of writes is grouped into one rebuild (ms), and the quiet time that ends a
#: burst (ms): an editor's save is a few writes within ~10 ms; a rebuild waits at most this long.
DEBOUNCE_MS = 400
STEP_MS = 30
#: How long the watch blocks in Rust before checking for Ctrl-C, the stop event and the files'
#: signatures (ms).
RUST_TIMEOUT_MS = 500
#: How far a file's modification time may lag the clock (ns): the kernel stamps it from a coarse
#: clock, up to one tick (4-10 ms) behind; twice the slowest tick.
MTIME_LAG_NS = 20_000_000


class Watcher:
    """Rebuild and publish on each change. ``session``: a LiveSession; ``hub``: the view's Hub;
    ``say``: where lines go; ``write``: an exports root to publish into after each good frame
    (None: nothing under exports/ changes); ``ocp``: a rigcad.live.ocp.OcpPush or None."""

    def __init__(self, session, hub, say=print, write: Path | None = None, ocp=None) -> None:
        self.session, self.hub, self.say, self.write, self.ocp = session, hub, say, write, ocp
        self.frames: list[dict] = []  # per frame: seq, timings (s), push (s), error: for the bench
        self._seen: tuple = ()

    def rebuild(self) -> None:
        """One update: parts first (published at once), then the check rows, then the extras."""
        before = {entry[0]: entry for entry in self._signature()}
        start = time.time_ns() - MTIME_LAG_NS
        frame = self.session.update()
        # what this rebuild has seen, over the files it found (the update may find more, or fewer when the
        # profile no longer reads): a file watched before keeps its entry from before the update (an edit
        # made during the update still counts); a file the update found, its entry now, unless its content
        # changed after the update started (then unknown: the next check rebuilds). A signature over another
        # set than the loop compares with would read as an edit no one made: a spurious frame after the
        # start, and each error said twice.
        self._seen = tuple(before.get(entry[0], entry if entry[3] is not None and entry[3] < start
                                      else (entry[0], None, None, None, None)) for entry in self._signature())
        self._publish(frame)
        if frame.error is not None:
            return
        if self.ocp is not None:
            self._push_ocp(frame)
        done = self.session.finish_check()
        if done is not None:
            self._publish(done)
            if done.error is not None:
                return
        if self.write is not None:
            self._write()

    def _push_ocp(self, frame) -> None:
        from rigcad.live.ocp import ViewerError

        try:
            self.ocp.push(self.session.good.rig, frame.rays)
        except ViewerError as err:  # the viewer went away: say so once, carry on with the browser view
            self.say(f"rigcad watch: {one_line(err)}; showing the browser view only")
            self.ocp = None

    def _publish(self, frame) -> None:
        push = self.hub.publish(frame)
        self.frames.append({"seq": frame.seq, "timings": dict(frame.timings), "push": push, "error": frame.error,
                            "ran": list(frame.ran), "at": time.time()})
        self.say(summary(frame, push))

    def _write(self) -> None:
        """Publish the exports of the good rig; a failure (a planted link, a full disk) is one line
        and the watch goes on (the previous exports stay whole: the publication is atomic)."""
        from rigcad.errors import RigcadError
        from rigcad.export.atomic import check_exports

        rig = self.session.good.rig
        t0 = time.perf_counter()
        try:
            check_exports(self.write, rig.name)
            result = rig.export(Path(self.write) / rig.name)
        except RigcadError as err:
            self.say(f"  not written: {one_line(err)}")
            return
        self.say(f"  wrote {Path(self.write) / rig.name}/: {len(result.rebuilt)} part(s) built, "
                 f"{len(result.reused)} unchanged ({time.perf_counter() - t0:.1f} s)")

    def _signature(self) -> tuple:
        """(file, the entry's inode and time, its content's time and size) of every watched file:
        what a rebuild has seen (a link renamed over a file changes the entry, not only the content)."""
        out = []
        for path in sorted(self.watched()):
            try:
                entry = path.lstat()
                st = path.stat()
                out.append((path, entry.st_ino, entry.st_mtime_ns, st.st_mtime_ns, st.st_size))
            except OSError:
                out.append((path, None, None, None, None))
        return tuple(out)

    def watched(self) -> frozenset[Path]:
        """The session's files (the profile's own path as found, links not followed, its extends:
        chain, the printers) and the spec itself when it names a path."""
        import os

        spec = Path(str(self.session.spec))
        extra = {Path(os.path.abspath(spec))} if os.path.lexists(spec) else set()
        return frozenset({Path(f) for f in self.session.files} | extra)

    def run(self, stop=None) -> None:
        """Build once, then rebuild on each change until ``stop`` (a threading.Event) is set or
        Ctrl-C (KeyboardInterrupt, raised to the caller)."""
        import watchfiles

        self.rebuild()
        while stop is None or not stop.is_set():
            files = self.watched()
            if not files:  # not even the profile's file was found: nothing to watch
                raise ProfileError(self.frames[-1]["error"] or f"no profile {self.session.spec!r}")
            names = {str(f) for f in files}
            folders = sorted({str(f.parent) for f in files})
            restarted = False
            for changes in watchfiles.watch(*folders, watch_filter=lambda _c, path: path in names,
                                            debounce=DEBOUNCE_MS, step=STEP_MS, stop_event=stop,
                                            rust_timeout=RUST_TIMEOUT_MS, yield_on_timeout=True, recursive=False):
                # an empty set: a quiet RUST_TIMEOUT_MS; a file changed while the watch was not yet
                # armed (restarted for a new extends: chain) is caught by its signature
                if not changes and self._signature() == self._seen:
                    continue
                self.rebuild()
                if self.watched() != files:  # the extends: chain changed: watch the new files
                    restarted = True
                    break
            if not restarted:
                return


def summary(frame, push: float) -> str:
    """One terminal line for ``frame``: what ran and how long each stage took, or the error."""
    head = f"[{frame.seq}] {frame.profile}:"
    if frame.error is not None:
        kept = " (the view keeps the last good rig)" if frame.parts else ""
        return f"{head} error: {one_line(frame.error)}{kept}"
    if frame.ran == ("check",):
        rows = frame.rows or []
        failed = [r for r in rows if not r["ok"]]
        text = (f"check: {len(rows)} rows pass" if not failed else
                f"check: {len(failed)} of {len(rows)} rows FAIL: " +
                "; ".join(f"{r['check']} {r['measured']:.4g} {r['unit']} not {r['relation']} {r['limit']:.4g}"
                          for r in failed))
        return f"{head} {text} ({frame.timings.get('check', 0.0):.2f} s)"
    parts = [n for n in frame.ran if n.startswith("mesh:")]
    stages = [n for n in frame.ran if not n.startswith("mesh:")]
    what = ", ".join(stages + ([f"{len(parts)} part(s): {', '.join(p[5:] for p in parts)}"] if parts else [])) or "nothing"
    times = " ".join(f"{k} {v:.2f}" for k, v in frame.timings.items())
    return f"{head} rebuilt {what} ({times} push {push:.2f} s){'; checking' if frame.check_pending else ''}"


__all__ = ["DEBOUNCE_MS", "STEP_MS", "Watcher", "summary"]
