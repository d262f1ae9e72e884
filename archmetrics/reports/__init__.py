"""Reports: one module per output format, each ``render_*(report) -> str``."""
