"""The exceptions dispex raises, one class per kind of failure (the library's Status codes).

Bad arguments raise the built-in TypeError (a value of the wrong type) or ValueError (a value
out of range, an unknown option); every other failure raises a subclass of dispex.Error with
the library's one-line message and what it is about.
"""

from typing import Any, Dict, Optional


def shown(value: Any) -> str:
    """`value` as messages show it: its repr, or for a long one (a whole array) its type and,
    for an array, its shape."""
    text = repr(value)
    if len(text) <= 60:
        return text
    shape = getattr(value, "shape", None)
    kind = type(value).__module__ + "." + type(value).__qualname__
    kind = kind.replace("builtins.", "")
    return f"<{kind} of shape {tuple(shape)}>" if shape is not None else f"<{kind}>"


class Error(RuntimeError):
    """A dispex failure.

    Attributes: code, the kind of failure as the library names it ("bad_input", "mismatch",
    "check_failed", "cancelled", "over_budget", "output", or "failed" for any other); path,
    the file it is about (None when not one file); face, the Ptex face it is about (None when
    not one face).
    """

    def __init__(self, message: str, *, code: str = "failed", path: Optional[str] = None,
                 face: Optional[int] = None) -> None:
        super().__init__(message)
        self.code = code
        self.path = path
        self.face = face


class InputError(Error):
    """A file or mesh that cannot be read or is malformed; path names the file."""


class MismatchError(Error):
    """Inputs that do not belong together: a sculpt that misses or is moved against its base,
    a base and sculpt swapped, farm shard parts made from other inputs."""


class VerifyError(Error):
    """A map that fails a bound verify was asked to check; report holds verify's whole report
    (a dict, as with check=False) and path the map."""

    def __init__(self, message: str, *, report: Optional[Dict[str, Any]] = None,
                 code: str = "check_failed", path: Optional[str] = None,
                 face: Optional[int] = None) -> None:
        super().__init__(message, code=code, path=path, face=face)
        self.report: Dict[str, Any] = report if report is not None else {}


class CancelledError(Error):
    """The work was cancelled (a signal the Python handlers did not turn into an exception)."""


class MemoryBudgetError(Error):
    """The work is estimated to need more memory than max_memory allows; nothing was done."""


class OutputError(Error):
    """An output that cannot be written (a folder that cannot be made, a full disk); path
    names it. Nothing is left behind: outputs appear whole or not at all."""


# Raised and printed as dispex.InputError, ..., the names the package exports.
for _error in (Error, InputError, MismatchError, VerifyError, CancelledError, MemoryBudgetError,
               OutputError):
    _error.__module__ = "dispex"
del _error
