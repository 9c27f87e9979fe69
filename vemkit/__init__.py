"""vemkit: lowest-order virtual elements for elastic bodies in frictional contact."""

__version__ = "0.1.0"
