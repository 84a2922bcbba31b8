"""The two test tiers: `make test` runs the fast one (everything not marked slow, freecad, linuxcnc or browser),
`make test-all` runs everything. A sweep (one property over many cases) keeps a few representative cases in the
fast tier, each taking a different path through the code, and runs the others in the slow tier only."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import pytest


def sweep(cases: Iterable, fast: Iterable, ids: Sequence[str] | None = None) -> list:
    """Parameters for @pytest.mark.parametrize: the cases named in `fast` as they are, every other case marked
    slow. A case is named by its id when `ids` are given (then pass no ids= to parametrize), else by its first
    argument (a tuple's first item, or the value itself). Every name in `fast` must name a case: a misspelt one
    would move the whole sweep out of the fast tier."""
    cases = list(cases)
    names = list(ids) if ids is not None else [case[0] if isinstance(case, tuple) else case for case in cases]
    fast = list(fast)
    unknown = [name for name in fast if name not in names]
    if unknown or len(names) != len(cases):
        raise ValueError(f"fast cases that are not cases of the sweep: {unknown}")
    params = []
    for index, (case, name) in enumerate(zip(cases, names)):
        values = case if isinstance(case, tuple) else (case,)
        params.append(pytest.param(*values, id=ids[index] if ids is not None else None,
                                   marks=() if name in fast else pytest.mark.slow))
    return params
