"""Named extension points: one small typed mapping from names to implementations.

softbend looks things up by name in several places: surrogate families,
transfer strategies, controllers, plants, rigs, campaign backends and material
models. Each keeps a :class:`Registry`; adding an implementation is one module
plus one ``register`` call, from inside the package or outside it::

    from softbend.control import CONTROLLERS, make_controller

    CONTROLLERS.register("my-pid", make_my_pid)       # once, at import time
    controller = make_controller("my-pid", table, gain=2.0)  # what the library does

An unknown name is one :class:`UnknownNameError` line listing the known names,
never a silent default; registering a name twice is refused unless asked for.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Generic, TypeVar

from softbend.errors import SoftbendError

__all__ = ["Registry", "UnknownNameError"]

T = TypeVar("T")


class UnknownNameError(SoftbendError, ValueError):
    """A name that no registry entry has; the message lists the known ones."""


class Registry(Generic[T]):
    """Names mapped to implementations of one kind of thing, in registration order.

    Parameters
    ----------
    kind : str
        What the entries are, as the user names it in an option or a file
        (``"controller"``, ``"surrogate family"``); it starts every error message.
    """

    def __init__(self, kind: str) -> None:
        if not isinstance(kind, str) or not kind.strip():
            raise ValueError(f"The 'kind' of a Registry must be a non-empty string. Got {kind!r}.")
        self.kind = kind
        self._entries: dict[str, T] = {}

    def register(self, name: str, entry: T, *, replace: bool = False) -> T:
        """Make ``entry`` available as ``name`` and return it (usable as a decorator's body).

        Parameters
        ----------
        name : str
            Lower-case name without spaces, as typed on a command line (``"bang-bang"``).
        entry : T
            The implementation: a class, a factory or a descriptor object.
        replace : bool
            Allow replacing an existing entry of the same name.

        Raises
        ------
        ValueError
            For a name that is empty, has spaces or upper case, or is taken (without
            ``replace``).
        """
        if not isinstance(name, str) or not name or name != name.strip().lower() or " " in name:
            raise ValueError(
                f"The name of a {self.kind} must be a non-empty lower-case string without "
                f"spaces, e.g. 'my-{self.kind.split()[-1]}'. Got {name!r}."
            )
        if name in self._entries and not replace:
            raise ValueError(
                f"The {self.kind} name {name!r} is already registered; pick another name or "
                "pass replace=True."
            )
        self._entries[name] = entry
        return entry

    def unregister(self, name: str) -> None:
        """Remove ``name`` (an unknown name raises :class:`UnknownNameError`)."""
        self.check(name)
        del self._entries[name]

    def check(
        self,
        name: object,
    ) -> str:
        """Return ``name`` if registered, else raise :class:`UnknownNameError`.

        Parameters
        ----------
        name : object
            The name to look up.

        Raises
        ------
        UnknownNameError
            ``Unknown controller 'x'; known: a, b.`` with no key: the caller that
            hands its parameter on names it with :func:`softbend.errors.keyed`.
        """
        if isinstance(name, str) and name in self._entries:
            return name
        raise UnknownNameError(
            f"Unknown {self.kind} {name!r}; known: {', '.join(self._entries) or 'none'}."
        )

    def get(
        self,
        name: object,
    ) -> T:
        """The entry registered as ``name``; an unknown name raises :class:`UnknownNameError`."""
        return self._entries[self.check(name)]

    def names(self) -> tuple[str, ...]:
        """Registered names, in registration order."""
        return tuple(self._entries)

    def items(self) -> tuple[tuple[str, T], ...]:
        """``(name, entry)`` pairs, in registration order."""
        return tuple(self._entries.items())

    def __contains__(self, name: object) -> bool:
        return name in self._entries

    def __iter__(self) -> Iterator[str]:
        return iter(tuple(self._entries))

    def __len__(self) -> int:
        return len(self._entries)

    def __repr__(self) -> str:
        return f"Registry({self.kind!r}: {', '.join(self._entries)})"
