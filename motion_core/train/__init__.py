"""Training programs: ``python -m motion_core.train WHAT ...`` (see ``__main__``)."""
