"""The user-facing apps: the command line, live replay, animation and export."""
