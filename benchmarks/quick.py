"""``--quick``: a benchmark's smoke-test settings, declared once, as values of its own options.

``--help`` prints them and ``--quick`` sets them (over any given), so the help, the run and
the docs, which point to ``--help``, cannot disagree.
"""

from __future__ import annotations

import argparse
from typing import Any


def add_quick(parser: argparse.ArgumentParser, **settings: Any) -> None:
    """Give ``parser`` a ``--quick`` that stands for ``settings`` (option dests and values;
    :func:`parse` refuses one the parser has no option for)."""
    shown = " ".join(f"--{name.replace('_', '-')} {value}" for name, value in settings.items())
    parser.add_argument(
        "--quick", action="store_const", const=settings, default=None, help=f"a smoke test: {shown}"
    )


def parse(parser: argparse.ArgumentParser, argv: Any = None) -> argparse.Namespace:
    """``parser``'s arguments, with the ``--quick`` settings applied when it was given."""
    args = parser.parse_args(argv)
    quick = args.quick or {}
    unknown = sorted(name for name in quick if not hasattr(args, name))
    if unknown:
        raise ValueError(f"--quick sets options the benchmark does not have: {unknown}")
    for name, value in quick.items():
        setattr(args, name, value)
    return args
