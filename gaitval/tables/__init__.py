"""Paper tables: tidy DataFrames rendered as CSV, Markdown and LaTeX."""
from gaitval.tables.render import write_table

__all__ = ["write_table"]
