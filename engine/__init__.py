"""Measuring engine: pure numpy, no I/O, no globals (design.md §2)."""
