"""Input files and their schema."""
