"""The machine interface (a Protocol) and its simulated implementation."""
