"""Native parts of the FMUs, compiled at build time (see python_loader.c)."""
