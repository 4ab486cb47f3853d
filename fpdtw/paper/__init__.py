"""The reproduction of the two papers, above the library: nothing in the library imports it."""
