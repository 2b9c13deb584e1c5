"""GPU ensembles (package map written below)."""
