"""torquesplit: dynamic load-sharing analysis of power-split gear transmissions."""

__version__ = "0.1.0"
