"""REBOUND behind one door: every raw pointer, struct offset and compiled callback lives here."""
