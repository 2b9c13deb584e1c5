"""Periodic steady state, speed sweeps and resonance maps (placeholder map, see below)."""
