"""Terminal tables: rich tables that keep every number whole on a narrow terminal.

On an 80-column terminal rich shrinks the columns of a wide table and cuts what no longer
fits with an ellipsis, so a dynamic factor printed as ``1.0657`` reads ``1.0…``.  A number
must never be shown truncated.  A table here measures itself first: where it is wider
than the terminal, it drops its vertical rules and edge padding and gives every column at
least the width of its widest data word (headers wrap at their spaces instead); only
what still does not fit folds onto a second line, never behind an ellipsis.
"""

from __future__ import annotations

from rich import box
from rich.table import Table as _RichTable

__all__ = ["Table"]


class Table(_RichTable):
    """:class:`rich.table.Table` that folds instead of cutting and goes compact when the
    terminal is too narrow for it."""

    def add_column(self, *args, **kwargs):
        kwargs.setdefault("overflow", "fold")
        return super().add_column(*args, **kwargs)

    def __rich_console__(self, console, options):
        natural = _RichTable.__rich_measure__(self, console,
                                              options.update(width=10_000))
        if natural.maximum > options.max_width:
            self.box = box.SIMPLE_HEAD
            self.pad_edge = False
            self.padding = (0, 0)  # the rule-less box still puts one space between columns
            for col in self.columns:
                words = [len(w) for cell in col._cells for w in str(cell).split()]
                if words:
                    col.min_width = max(col.min_width or 0, max(words))
        yield from super().__rich_console__(console, options)

