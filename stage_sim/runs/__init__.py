"""Whole runs in the core alone: controllers driving a simulation, and what a run achieved (stalls, coverage)."""
