"""pymoo-rail: energy-efficient train driving as pymoo problems and algorithms."""

__version__ = "0.1.0"
