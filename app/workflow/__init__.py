"""The measuring workflow: sessions per task, P1..Pn, NC Start, Calculate (spec/jog-measuring.md §3)."""
