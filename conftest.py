"""Repository root marker: makes pytest put this checkout first on sys.path."""
