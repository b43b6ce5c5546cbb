"""The plane assistant: placements of the slicing planes that give a stable, buildable design
(the method: plane_search/searcher.py's docstring)."""
from .searcher import *  # noqa: F401,F403
from .searcher import _figures, _record, _summary  # noqa: F401
