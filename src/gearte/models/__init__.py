"""Pure physics models, one module per phenomenon: functions of arrays, units mm, N, N·mm, MPa, rad."""
