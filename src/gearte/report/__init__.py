"""Reports: ``results.json`` and a self-contained ``report.html`` with embedded plots."""

from gearte.report.outputs import write_outputs

__all__ = ["write_outputs"]
