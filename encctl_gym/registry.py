"""One registry helper for every choice made by name (breakers, estimators, cost models, rewards,
features, learning algorithms, ...).

A :class:`Registry` is a read-only mapping ``name -> entry`` (usually a class) with one lookup
that names the registered choices when a name is unknown, and one builder that checks a class's
options against its constructor before calling it. A new choice is one class and one row
(:meth:`Registry.register`, also usable as a class decorator).

Base layer: imports only :mod:`encctl_gym.errors` and :mod:`encctl_gym._validation`.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Iterable, Iterator, Mapping
from typing import Any, Generic, TypeVar

from ._validation import format_value
from .errors import EncctlError, ParameterError

__all__ = ["Registry"]

T = TypeVar("T")


class Registry(Mapping[str, T], Generic[T]):
    """Names -> entries of one kind, looked up and built the same way for every kind.

    Parameters
    ----------
    kind : str
        What an entry is, for messages (``"breaker"``, ``"estimator"``, ...).
    entries : mapping or iterable, optional
        ``{name: entry}``, or entries that carry their name in the attribute ``name``.
    error : type of EncctlError, default ParameterError
        The exception raised for an unknown name or option (the command-line layers use
        :class:`~encctl_gym.errors.ConfigError`).

    Examples
    --------
    >>> class Loud:
    ...     name = "loud"
    ...     def __init__(self, volume=1):
    ...         self.volume = volume
    >>> SOUNDS = Registry("sound", [Loud])
    >>> SOUNDS.build("loud", volume=3).volume
    3
    >>> SOUNDS.options("loud")
    ('volume',)
    """

    def __init__(
        self, kind: str, entries: Mapping[str, T] | Iterable[T] = (), *, error: type[EncctlError] = ParameterError
    ) -> None:
        self.kind = kind
        self.error = error
        self._entries: dict[str, T] = {}
        items = entries.items() if isinstance(entries, Mapping) else ((self._name_of(e), e) for e in entries)
        for name, entry in items:
            self.register(entry, name=name)

    @staticmethod
    def _name_of(entry: Any) -> str:
        name = getattr(entry, "name", None)
        if not isinstance(name, str) or not name:
            raise ParameterError(f"{format_value(entry)} has no registry name (a non-empty str attribute 'name')")
        return name

    # -- the mapping
    def __getitem__(self, name: str) -> T:
        return self._entries[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._entries)

    def __len__(self) -> int:
        return len(self._entries)

    def __repr__(self) -> str:
        return f"Registry({self.kind!r}, [{', '.join(self._entries)}])"

    # -- rows
    def register(self, entry: T, name: str | None = None) -> T:
        """Add ``entry`` under ``name`` (default: its ``name`` attribute) and return it, so that
        ``@REGISTRY.register`` decorates a class. A name is registered once."""
        key = self._name_of(entry) if name is None else name
        if not isinstance(key, str) or not key:
            raise ParameterError(f"a {self.kind} name must be a non-empty str, got {format_value(key)}")
        if key in self._entries:
            raise ParameterError(f"a {self.kind} named {key!r} is already registered ({format_value(self._entries[key])})")
        self._entries[key] = entry
        return entry

    def names(self) -> list[str]:
        """The registered names, in registration order."""
        return list(self._entries)

    # -- lookup and build
    def lookup(self, name: Any) -> T:
        """The entry registered as ``name``; :attr:`error` naming the registered ones otherwise."""
        try:
            return self._entries[name]
        except (KeyError, TypeError):
            raise self.error(f"unknown {self.kind} {format_value(name)}; choose one of {', '.join(self._entries)}") from None

    def options(self, name: Any) -> tuple[str, ...]:
        """The keyword options of the entry ``name``: the parameters of its constructor (or of
        the callable itself), without ``*args`` and ``**kwargs``."""
        entry = self.lookup(name)
        target: Callable[..., Any] = entry  # type: ignore[assignment]
        try:
            params = inspect.signature(target).parameters.values()
        except (TypeError, ValueError):  # a builtin without a signature
            return ()
        return tuple(p.name for p in params if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY))

    def check_options(self, name: Any, options: Iterable[str]) -> None:
        """Raise :attr:`error` if an option is not one of :meth:`options` (the message lists them)."""
        known = self.options(name)
        unknown = [k for k in options if k not in known]
        if unknown:
            raise self.error(
                f"the {self.kind} {name!r} has no option {', '.join(format_value(k) for k in unknown)}; "
                f"its options: {', '.join(known) or 'none'}"
            )

    def build(self, name: Any, /, **options: Any) -> Any:
        """Call the entry ``name`` with ``options`` after checking them (:meth:`check_options`)."""
        entry = self.lookup(name)
        self.check_options(name, options)
        return entry(**options)  # type: ignore[operator]
