"""General tolerance engine: distributions, stack-up, Monte-Carlo and contributions."""
