"""Live: the verdict re-solved in the background while a plane moves (engine.py), its state and
the reader the tests and the bench use (state.py)."""
