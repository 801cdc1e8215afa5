"""The benchmark suite: `python -m bench` (or `scenario bench`). See bench/__main__.py."""
