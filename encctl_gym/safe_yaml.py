"""Safe YAML: the package's one reader of YAML, bounded before any Python object is built.

Every YAML document the package reads goes through :func:`load_yaml` (a text) or
:func:`read_yaml_file` (a file, read by :func:`~encctl_gym._validation.read_bounded`): plant
files (:mod:`encctl_gym.plant_file`), training configurations and their ``--set`` values
(:mod:`encctl_gym.agents.config`). The parser's events are composed into nodes by an iterative
composer that enforces, while it reads:

* a nesting of at most ``max_depth`` mappings and lists (PyYAML builds nested values
  recursively; libyaml stops at 1000 levels, the pure-Python parser not at all);
* no alias at all (``aliases=False``), or aliases whose expansion stays within ``max_nodes``:
  each anchored node's expanded size is known when it closes, so an alias adds that size
  without being expanded (a few hundred bytes of nested aliases, the "billion laughs", would
  otherwise build gigabytes); an alias inside the node it names (a recursive alias) is refused;
* at most ``max_nodes`` nodes in all, aliases counted expanded;
* no key given twice in a mapping (the same key text: PyYAML would keep the last one silently),
  and no key given by two merges (``<<:`` twice, or ``<<: [*a, *b]`` with a key in both: PyYAML
  keeps one silently); a key written out beside a merge overrides the merged one, as YAML says.

Only then are Python objects built, by PyYAML's safe constructor (no ``!!python/...`` tags).
A number with an exponent but no dot (``1e-6``, ``442e15``) is a number, as in JSON and YAML
1.2 (PyYAML's YAML 1.1 reads it as a string); a quoted value stays a string. The C parser
(libyaml) is used when PyYAML has it. Every failure is one line: a :class:`ConfigError` for a
document that cannot be read, ``limit_error`` (:class:`ResourceLimitError` unless the caller
says otherwise) for one over a bound, naming the document and the bound.
"""

from __future__ import annotations

import functools
import os
import re
from typing import Any

from ._validation import format_value, read_bounded
from .errors import ConfigError, EncctlError, ResourceLimitError

__all__ = ["load_yaml", "read_yaml_file"]

# YAML 1.1 (PyYAML) reads ``1e-6`` and ``442e15`` as strings, since its floats need a dot; YAML
# 1.2, JSON and the command line read them as numbers, and so does every YAML the package reads
_EXPONENT_FLOAT = r"^[-+]?[0-9][0-9_]*(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"
_MERGE_TAG = "tag:yaml.org,2002:merge"


@functools.lru_cache(maxsize=1)
def _loader_class() -> Any:
    """PyYAML's safe loader (the C one when available) that also reads ``1e-6`` as a float."""
    import yaml

    base = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    loader: Any = type("EncctlSafeLoader", (base,), {})
    loader.add_implicit_resolver("tag:yaml.org,2002:float", re.compile(_EXPONENT_FLOAT), list("-+0123456789"))
    return loader


class _Open:
    """A mapping or list being composed: its node, its expanded size so far, and (a mapping) the
    key waiting for its value and the keys seen."""

    __slots__ = ("node", "size", "key", "seen", "anchored")

    def __init__(self, node: Any, anchored: bool) -> None:
        self.node = node
        self.size = 1
        self.key: Any = None
        self.seen: set[tuple[str, str]] = set()
        self.anchored = anchored


def _where(stack: list[_Open], key: str) -> str:
    """The dotted path of ``key`` from the top (``env.preset``, ``A[2]``), for messages."""
    import yaml

    parts: list[str] = []
    for frame in stack[:-1]:
        if isinstance(frame.node, yaml.SequenceNode):
            parts.append(f"[{len(frame.node.value)}]")
        elif frame.key is not None and isinstance(frame.key, yaml.ScalarNode):
            parts.append(("." if parts else "") + str(frame.key.value))
    return "".join(parts) + ("." if parts else "") + key


def _compose(loader: Any, what: str, max_nodes: int, max_depth: int, aliases: bool, limit_error: type[EncctlError]) -> Any:
    """The single document's root node (``None`` for an empty stream), every bound checked on
    the way (module docstring); mirrors PyYAML's ``Composer`` without its recursion (and without
    its path resolvers, which the safe loader does not have)."""
    import yaml

    loader.get_event()  # StreamStartEvent
    if loader.check_event(yaml.StreamEndEvent):
        loader.get_event()
        return None
    loader.get_event()  # DocumentStartEvent
    anchors: dict[str, Any] = {}
    sizes: dict[int, int] = {}  # expanded size of each complete anchored node, by identity
    stack: list[_Open] = []
    used_alias = False
    while True:
        event = loader.get_event()
        if isinstance(event, (yaml.SequenceEndEvent, yaml.MappingEndEvent)):
            frame = stack.pop()
            frame.node.end_mark = event.end_mark
            child, size = frame.node, frame.size
            if frame.anchored:
                sizes[id(child)] = size
        elif isinstance(event, yaml.AliasEvent):
            if not aliases:
                raise ConfigError(f"{what} uses a YAML alias (*{event.anchor}); write the values out")
            if event.anchor not in anchors:
                raise ConfigError(
                    f"cannot read {what}: found undefined alias {format_value(event.anchor)}{_at(event.start_mark)}"
                )
            child, used_alias = anchors[event.anchor], True
            if id(child) not in sizes:
                raise ConfigError(f"{what}: a YAML alias refers to a node that contains it (recursive alias)")
            size = sizes[id(child)]
        else:
            anchor = event.anchor
            if anchor is not None and anchor in anchors:
                raise ConfigError(f"cannot read {what}: found duplicate anchor {format_value(anchor)}{_at(event.start_mark)}")
            tag = event.tag
            if isinstance(event, yaml.ScalarEvent):
                if tag is None or tag == "!":
                    tag = loader.resolve(yaml.ScalarNode, event.value, event.implicit)
                child = yaml.ScalarNode(tag, event.value, event.start_mark, event.end_mark, style=event.style)
                size = 1
                if anchor is not None:
                    anchors[anchor], sizes[id(child)] = child, 1
            else:
                kind = yaml.SequenceNode if isinstance(event, yaml.SequenceStartEvent) else yaml.MappingNode
                if tag is None or tag == "!":
                    tag = loader.resolve(kind, None, event.implicit)
                node = kind(tag, [], event.start_mark, None, flow_style=event.flow_style)
                if len(stack) >= max_depth:
                    raise ConfigError(f"{what} nests mappings or lists more than {max_depth} levels deep")
                if anchor is not None:
                    anchors[anchor] = node
                stack.append(_Open(node, anchor is not None))
                continue
        if not stack:
            root = child
            break
        parent = stack[-1]
        parent.size += size
        if parent.size > max_nodes:
            if used_alias:
                raise limit_error(
                    f"{what}: its YAML aliases expand to more than {max_nodes} nodes; write the values out instead of nesting aliases"
                )
            raise limit_error(f"{what} holds more than {max_nodes} YAML nodes")
        if isinstance(parent.node, yaml.SequenceNode):
            parent.node.value.append(child)
        elif parent.key is None:
            parent.key = child
            if isinstance(child, yaml.ScalarNode) and child.tag != _MERGE_TAG:
                if (child.tag, child.value) in parent.seen:
                    raise ConfigError(f"{what}: field {format_value(_where(stack, child.value))} is given more than once")
                parent.seen.add((child.tag, child.value))
        else:
            parent.node.value.append((parent.key, child))
            parent.key = None
    loader.get_event()  # DocumentEndEvent
    if not loader.check_event(yaml.StreamEndEvent):
        raise ConfigError(f"cannot read {what}: it holds more than one YAML document{_at(loader.get_event().start_mark)}")
    loader.get_event()
    return root


def _merged_keys(source: Any) -> list[str]:
    """The scalar keys a merge source gives: a mapping's own keys and those of its merges."""
    import yaml

    sources = source.value if isinstance(source, yaml.SequenceNode) else [source]
    keys: list[str] = []
    for node in sources:
        if not isinstance(node, yaml.MappingNode):
            continue  # PyYAML's constructor refuses a merge of anything else, with its own message
        for key, value in node.value:
            if isinstance(key, yaml.ScalarNode):
                keys.extend(_merged_keys(value) if key.tag == _MERGE_TAG else [key.value])
    return keys


def _check_merges(root: Any, what: str) -> None:
    """Refuse a mapping whose merges (``<<:``) give one key twice (module docstring); each node
    is visited once, so a document of shared aliases is not walked once per alias."""
    import yaml

    seen: set[int] = set()
    todo = [] if root is None else [root]
    while todo:
        node = todo.pop()
        if id(node) in seen or not isinstance(node, (yaml.MappingNode, yaml.SequenceNode)):
            continue
        seen.add(id(node))
        if isinstance(node, yaml.SequenceNode):
            todo.extend(node.value)
            continue
        merged: set[str] = set()
        for key, value in node.value:
            todo.append(value)
            if isinstance(key, yaml.ScalarNode) and key.tag == _MERGE_TAG:
                for name in _merged_keys(value):
                    if name in merged:
                        raise ConfigError(f"{what}: field {format_value(name)} is given by two merges (<<)")
                    merged.add(name)


def _at(mark: Any) -> str:
    return "" if mark is None else f" (line {mark.line + 1}, column {mark.column + 1})"


def _reason(exc: BaseException) -> str:
    """One line for a parser or constructor failure: context, problem and where."""
    import yaml

    if isinstance(exc, yaml.MarkedYAMLError):
        text = ": ".join(part for part in (exc.context, exc.problem) if part)
        return format_value(text + _at(exc.problem_mark or exc.context_mark), limit=200)
    return format_value(" ".join(str(exc).split()) or type(exc).__name__, limit=200)


def load_yaml(
    text: str, *, what: str, max_nodes: int, max_depth: int, aliases: bool, limit_error: type[EncctlError] = ResourceLimitError
) -> Any:
    """The value of the single YAML document ``text``, composed within the bounds (module docstring).

    Parameters
    ----------
    text : str
        The document.
    what : str
        What it is, for messages (``"system file 'plant.yaml'"``, ``"override value '[1, 2]'"``).
    max_nodes : int
        Most nodes, aliases counted expanded.
    max_depth : int
        Deepest nesting of mappings and lists (the top-level mapping is one level).
    aliases : bool
        Whether aliases (``*name``) are allowed at all.
    limit_error : type of EncctlError, default ResourceLimitError
        Raised for a document over ``max_nodes``.

    Returns
    -------
    object
        What PyYAML's safe loader builds (``None`` for an empty document).

    Raises
    ------
    ConfigError
        For a syntax error, an unsafe or unknown tag, an integer of over 4300 digits, more than
        one document, a refused or recursive alias, nesting deeper than ``max_depth``, or a key
        given twice in a mapping.
    ResourceLimitError
        (or ``limit_error``) for more than ``max_nodes`` nodes.
    """
    import yaml

    loader = _loader_class()(text)
    try:
        try:
            root = _compose(loader, what, max_nodes, max_depth, aliases, limit_error)
            _check_merges(root, what)
            return None if root is None else loader.construct_document(root)
        except EncctlError:  # the bounds' own errors (a ParameterError is a ValueError)
            raise
        except yaml.MarkedYAMLError as exc:
            if "maximum nesting depth" in str(exc.problem):  # libyaml's own bound (1000 > max_depth)
                raise ConfigError(f"{what} nests mappings or lists more than {max_depth} levels deep") from None
            syntax = "" if isinstance(exc, yaml.constructor.ConstructorError) else "not valid YAML: "
            raise ConfigError(f"cannot read {what}: {syntax}{_reason(exc)}") from None
        except (yaml.YAMLError, ValueError) as exc:  # ValueError: an integer of over 4300 digits
            raise ConfigError(f"cannot read {what}: {_reason(exc)}") from None
    finally:
        loader.dispose()


def read_yaml_file(
    path: str | os.PathLike[str],
    *,
    what: str,
    max_bytes: int,
    limit_name: str,
    max_nodes: int,
    max_depth: int,
    aliases: bool,
    limit_error: type[EncctlError] = ResourceLimitError,
) -> Any:
    """The value of the YAML file ``path``: at most ``max_bytes`` read
    (:func:`~encctl_gym._validation.read_bounded`, naming ``limit_name``), UTF-8, then
    :func:`load_yaml` with the same bounds.

    Parameters
    ----------
    path : str or os.PathLike
        The file (the caller checks first that it is a regular file where a FIFO could block).
    what : str
        What the file is (``"config file"``); messages name it with the path.
    max_bytes : int
        Largest file read.
    limit_name : str
        The constant that holds ``max_bytes``, named in the message.
    max_nodes, max_depth, aliases, limit_error
        As in :func:`load_yaml`; ``limit_error`` is also raised for a file over ``max_bytes``.

    Raises
    ------
    ConfigError
        If the file cannot be read, is not UTF-8, or :func:`load_yaml` refuses it.
    ResourceLimitError
        (or ``limit_error``) for a file over ``max_bytes`` or a document over ``max_nodes``.
    """
    raw = read_bounded(what, path, max_bytes, limit_name, error=limit_error)
    label = f"{what} {os.fspath(path)!r}"
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError(f"cannot read {label}: {_reason(exc)}") from None
    return load_yaml(text, what=label, max_nodes=max_nodes, max_depth=max_depth, aliases=aliases, limit_error=limit_error)
