"""The version of gearte (one place; ``gearte.__version__`` re-exports it)."""

__version__ = "0.1.0"
