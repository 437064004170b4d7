"""Pure physics models, one module per phenomenon, as functions of arrays."""
