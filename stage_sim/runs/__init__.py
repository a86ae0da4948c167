"""Whole runs in the core alone: controllers driving a simulation, what a run achieved (stalls, coverage), and
how a run is stopped cleanly (Ctrl-C, SIGTERM)."""
