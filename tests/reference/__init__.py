"""Test-only references: plain-numpy steps of the window methods and synthetic motions."""
