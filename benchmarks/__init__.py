"""Benchmarks and studies: programs that print figures (``./run py -m benchmarks.NAME``)."""
