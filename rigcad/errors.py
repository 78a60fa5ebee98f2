"""One exception family for rigcad.

Every message names what is wrong, where (file and line when the value came from a profile),
the offending value and what would be valid. The CLI prints ``str(err)`` on one line and exits
with ``err.exit_code``; a traceback reaching the user is a bug.
"""

from __future__ import annotations


class RigcadError(Exception):
    """Base of every error rigcad raises on purpose."""

    exit_code = 2

    def __init__(self, message: str, *, where: str | None = None, param: str | None = None) -> None:
        self.message = message
        self.where = where
        #: The profile key to blame ("section.key"), so a later stage can add its file:line.
        self.param = param
        super().__init__(f"{where}: {message}" if where else message)

    def located(self, marks: dict[tuple[str, ...], str]) -> "RigcadError":
        """The same error with ``where`` filled in from a profile's marks, if it names a parameter."""
        if self.where is not None or self.param is None:
            return self
        where = marks.get(tuple(self.param.split(".")))
        return type(self)(self.message, where=where, param=self.param) if where else self


class ProfileError(RigcadError):
    """A profile is unreadable, has an unknown or missing key, a bad unit or an out-of-range value."""


class GeometryError(RigcadError):
    """Valid-looking parameters that describe an impossible rig (rays miss, parts collide)."""


class KernelError(GeometryError):
    """The CAD kernel (OpenCascade) could not build a part the profile describes: the message names
    the part, the profile keys that shape it and a way out. Exit code 1, like a failed check: the
    profile was valid, the part was not buildable."""

    exit_code = 1


class AssemblyError(GeometryError):
    """No order puts the rig together: ``step`` (the assembly step that cannot be done, placing the
    parts ``members``) runs into ``obstacles`` (parts, or the steps whose fasteners are in the way).
    Exit code 1: the profile was valid, the rig it describes cannot be assembled. ``summary``: the
    real blocker in one phrase (the parts that collide, and why no order avoids it); ``detail``: the
    check's whole reason when the message is a one-line digest of it."""

    exit_code = 1

    def __init__(self, message: str, *, step: str | None = None, members: tuple[str, ...] = (),
                 obstacles: tuple[str, ...] = (), where: str | None = None, param: str | None = None,
                 summary: str = "", detail: str = "") -> None:
        super().__init__(message, where=where, param=param)
        self.step, self.members, self.obstacles = step, tuple(members), tuple(obstacles)
        self.summary, self.detail = summary, detail


class IntegrationError(RigcadError):
    """The dome integrator failed or could not meet its requested tolerance."""


class ExportError(RigcadError):
    """Writing or re-reading an export failed."""


class WriteError(ExportError):
    """An output could not be written (no space, permission, read-only, a file vanished): the
    message names the path and what to do; the previous outputs are unchanged. Exit code 1."""

    exit_code = 1


class CheckError(RigcadError):
    """A declared tolerance is not met (ray check, mesh check)."""

    exit_code = 1


class FabricationError(RigcadError):
    """Slicing, splitting or printer fit failed."""


class BasisError(RigcadError):
    """Basis-illumination maths refused its input: a bad zone, order, sampling, BRDF parameter or BRDF file."""


def one_line(message: object) -> str:
    """``message`` on one line: a newline or other control character that a name, a path or a value
    brought into it is shown escaped (``\\n``), never printed."""
    return "".join(ch if ch.isprintable() else ch.encode("unicode_escape").decode("ascii") for ch in str(message))
