"""A node the case's command misspells (it is never run)."""
