"""A progress bar over simulated time, shown on a terminal only."""
from __future__ import annotations

import sys


def progress_bar(progress, t_end):
    """A tqdm bar over simulated time, or None (progress=None: only on a terminal)."""
    if progress is None:
        progress = sys.stderr.isatty()
    if not progress:
        return None
    from tqdm import tqdm
    return tqdm(total=t_end, unit="s", desc="simulate", leave=False,
                bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} s [{elapsed}<{remaining}]")
