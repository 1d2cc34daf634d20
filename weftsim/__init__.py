"""weftsim: weft insertion mechanism of a rapier loom with a clearance joint."""

__version__ = "0.1.0"
