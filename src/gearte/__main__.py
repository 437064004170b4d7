from gearte.cli import entry

entry()
