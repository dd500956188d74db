"""rockfrag.report.text - text pages (contents, methods, limitations, tables) laid out on the page size.

Input : a list of ``Item`` (heading, paragraph, bullet, table, note). Output: the items split over as
many pages as they need (``paginate``, pure: the page count is known before anything is drawn), each
page drawn as a figure (``draw_text_page``) and written as HTML (``items_html``).
"""

from __future__ import annotations

import html
import textwrap
from dataclasses import dataclass, field, replace

import matplotlib.lines

from rockfrag.report.layout import new_page

TOP, BOTTOM = 0.925, 0.085  # figure fractions available to text
LINE = 0.021  # one line of 9.5 pt text on the A4-landscape page [figure fraction]
WRAP = 150  # characters per line of 9.5 pt text across the page
CHAR = 0.0062  # width of one 8.5 pt table character [figure fraction], for column positions
LEFT = 0.02
STRETCH = 7  # lines the last page of a run may hold beyond its capacity, set closer together
SHORT_TABLE = 10  # rows of a table that is never split across pages where it fits one page
MIN_HEADER = 12  # characters: a header is not wrapped narrower than this to make a table fit


@dataclass
class Item:
    """kind: heading | paragraph | strong | bullet | table | note; text, or header + rows for a table.

    ``part`` is the index of the section the item belongs to when several sections share pages (``pack``);
    ``anchor`` the HTML id of a heading that starts a section part-way down a page (the contents links it).
    """

    kind: str
    text: str = ""
    header: list = field(default_factory=list)
    rows: list = field(default_factory=list)
    part: int = 0
    anchor: str = ""


def heading(text: str) -> Item:
    """A section heading (two lines of the page)."""
    return Item("heading", text)


def paragraph(text: str) -> Item:
    """A paragraph, wrapped to the page width and followed by a blank line."""
    return Item("paragraph", text)


def strong(text: str) -> Item:
    """A paragraph in bold: the verdict of an answer page."""
    return Item("strong", text)


def bullet(text: str) -> Item:
    """One item of a bullet list."""
    return Item("bullet", text)


def note(text: str) -> Item:
    """A note in smaller italic type."""
    return Item("note", text)


def table(header, rows) -> Item:
    """A table: ``header`` a list of column titles, ``rows`` lists of cells (each cell shown as ``str``).

    A row whose only text is its first cell is a group heading (``is_span``): drawn in bold across the table,
    its text does not widen the first column.
    """
    return Item("table", header=[str(h) for h in header], rows=[[str(c) for c in row] for row in rows])


def is_span(row) -> bool:
    """A table row that heads a group of rows: text in the first cell only, drawn across the table."""
    return len(row) > 1 and bool(row[0]) and not any(row[1:])


def _header_lines(item) -> int:
    return len(table_layout(item)[0][0]) if item.header else 1


def _lines(item) -> int:
    if item.kind == "heading":
        return 2
    if item.kind == "table":
        return len(item.rows) + 1 + _header_lines(item)
    width = WRAP - (4 if item.kind == "bullet" else 0)
    return max(1, len(textwrap.wrap(item.text, width))) + (1 if item.kind in ("paragraph", "strong") else 0)


BALANCE = 0.5
"""A run's last page holding less than this share of a page shares the last two pages' lines evenly instead."""


def paginate(items, capacity=None) -> list[list[Item]]:
    """Split items into pages of ``capacity`` lines (default: a full page).

    A table too wide for the page is split first (``fit_table``); a table longer than a page is split with its
    header repeated; a heading never ends a page. When what
    is left overflows the last page by at most ``STRETCH`` lines, it goes on that page with its lines set
    closer (``draw_text_page``) rather than alone on a near-empty page; when it is more, and the last page would
    hold less than ``BALANCE`` of a page, the last two pages share their lines evenly (no near-empty page).
    """
    capacity = capacity or int((TOP - BOTTOM) / LINE)
    pages = _paginate(items, capacity)
    if len(pages) >= 2 and sum(_lines(item) for item in pages[-1]) < BALANCE * capacity:
        tail = _joined_tables(pages[-2] + pages[-1])
        total = sum(_lines(item) for item in tail)
        for target in range(-(-total // 2), capacity):
            even = _paginate(tail, target, stretch=0)
            if len(even) == 2:
                return pages[:-2] + even
    return pages


def _joined_tables(items) -> list[Item]:
    """Consecutive pieces of one table (split by a page break: same header, same part) joined again."""
    joined = []
    for item in items:
        last = joined[-1] if joined else None
        if last is not None and item.kind == last.kind == "table" and item.header == last.header \
                and item.part == last.part:
            rows = item.rows[1:] if item.rows and _is_continued(item.rows[0]) else item.rows
            joined[-1] = replace(last, rows=last.rows + rows)
        else:
            joined.append(item)
    return joined


def _paginate(items, capacity: int, stretch: int = STRETCH) -> list[list[Item]]:
    """``paginate`` without the balancing of its last two pages; ``stretch`` as ``STRETCH``."""
    pages, current, used = [], [], 0
    queue = [part for item in items for part in fit_table(item)]
    while queue:
        if sum(_lines(rest) for rest in queue) <= capacity - used + stretch:  # the rest fits, a little closer
            current += queue
            break
        item = queue.pop(0)
        need = _lines(item)
        if item.kind == "table" and need > capacity - used:
            room = capacity - used - 1 - _header_lines(item)
            # a short table that would leave a few rows (its verdict rows, say) alone on the next page goes there
            # whole (cold read 12: a design-life table's steel part had its β and action rows cut off)
            whole = need <= capacity and len(item.rows) <= SHORT_TABLE
            if (room < 3 or whole) and current:
                carried = []
                while current and _leads_to_table(current[-1]):  # a heading or lead-in goes with its table
                    carried.insert(0, current.pop())
                if current:
                    pages.append(current)
                current, used = carried, sum(_lines(c) for c in carried)
                queue.insert(0, item)
                continue
            room = max(room, 3)
            if len(item.rows) - room == 1 and room > 3:
                room -= 1  # no single row alone under a repeated header on the next page: it takes two
            while 1 < room < len(item.rows) and (not item.rows[room][0] or is_span(item.rows[room - 1])):
                room -= 1  # a wrapped cell's lines stay on one page, and a group heading with its first row
            head = replace(item, rows=item.rows[:room])
            rest = item.rows[room:]
            opens = [] if not rest or is_span(rest[0]) else [_continued_row(item.rows[:room], len(item.header))]
            tail = replace(item, rows=opens + rest)
            current.append(head)
            pages.append(current)
            current, used = [], 0
            if tail.rows:
                queue.insert(0, tail)
            continue
        if used + need > capacity and current:
            follows = item.kind == "table"
            if current[-1].kind == "heading" or (follows and _leads_to_table(current[-1])):
                # keep the headings (a section's, then its first) and a table's lead-in with what follows
                kept = 1
                while kept < len(current) and (current[-1 - kept].kind == "heading"
                                               or (follows and _leads_to_table(current[-1 - kept]))):
                    kept += 1
                if kept < len(current):  # a page of headings only stays as it is
                    pages.append(current[:-kept])
                    current = current[-kept:]
                    used = sum(_lines(c) for c in current)
            else:
                pages.append(current)
                current, used = [], 0
        current.append(item)
        used += need
    if current or not pages:
        pages.append(current)
    return pages


CONTINUED = " (continued)"


def _continued_row(rows_before, columns: int) -> list[str]:
    """The group heading that opens the rest of a split table: the last group's name, "(continued)" after it.

    Not added where the rest opens with a group of its own (its heading says where the page starts).

    A table split across pages repeats its header; this row says the page goes on with the table (cold read 8,
    user C11), and with which group (an asset or a soil) where the table has groups.
    """
    group = next((row[0] for row in reversed(rows_before) if is_span(row)), "").removesuffix(CONTINUED.strip())
    return [(group + CONTINUED).strip() if group else CONTINUED.strip()] + [""] * (columns - 1)


def _is_continued(row) -> bool:
    return is_span(row) and row[0].endswith(CONTINUED.strip())


def _leads_to_table(item) -> bool:
    """A heading, or a paragraph or note that ends with a colon: it introduces what follows and goes with it."""
    return item.kind == "heading" or (item.kind in ("paragraph", "note") and item.text.rstrip().endswith(":"))


TABLE_CHARS = int((0.985 - LEFT - 0.01) / CHAR)  # characters of 8.5 pt type across the page


TABLE_SIZE = 8.5  # pt, table type; smaller (down to MIN_TABLE_SIZE) only for a table too wide for the page
WRAPPED_MIN = 24  # characters: a column wrapped no narrower stays readable, so its table is not split (fit_table)
MIN_TABLE_SIZE = 7.5  # pt: below it a client cannot read a printed table; a wider table is split (fit_table)


def _column_widths(item) -> list[int]:
    """Characters each column needs: its widest cell, or its header's longest line wrapped at ``MIN_HEADER``.

    The header as ``table_layout`` sets it at its narrowest ("P at 475 years" needs 8: "P at 475" / "years"), so a
    table is not wrapped or split for width its columns never take.
    """
    return [max(max((len(row[c]) for row in item.rows if not is_span(row)), default=0),
                max((len(line) for line in textwrap.wrap(item.header[c], MIN_HEADER, break_long_words=False)),
                    default=0)) for c in range(len(item.header))]


def fit_table(item) -> list[Item]:
    """A table as one or more tables that each fit the page width in type of at least ``MIN_TABLE_SIZE``.

    A table that fits is returned as it is. A wider one whose long cells fit wrapped onto lines of at least
    ``WRAPPED_MIN`` characters is returned wrapped (one table). Any other is split by columns, each part
    repeating the first column (the row's key: soil, block, damage state); a column still too wide with the
    key beside it has its cells wrapped onto continuation rows (the other cells blank). Nothing is cut. Any
    other item is returned as it is.

    Parameters
    ----------
    item : Item
        A table (or any item).

    Returns
    -------
    list of Item
    """
    if item.kind != "table" or not item.header:
        return [item]
    room = int(TABLE_CHARS * TABLE_SIZE / MIN_TABLE_SIZE)  # characters across the page at the smallest type
    widths = _column_widths(item)
    if sum(w + 2 for w in widths) <= room or len(widths) < 2:
        return [_wrapped_rows(item, room)]
    wrapped = _wrapped_rows(item, room)  # one table whose long cells wrap reads better than two halves of it
    after = _column_widths(wrapped)
    if sum(w + 2 for w in after) <= room and all(a >= min(b, WRAPPED_MIN) for a, b in zip(after, widths)):
        return [wrapped]
    groups, current = [], []
    for column in range(1, len(widths)):
        if current and widths[0] + 2 + sum(widths[c] + 2 for c in current + [column]) > room:
            groups.append(current)
            current = []
        current.append(column)
    groups.append(current)
    parts = []
    for columns in groups:
        keep = [0, *columns]
        part = replace(item, header=[item.header[c] for c in keep], rows=[[row[c] for c in keep] for row in item.rows])
        parts.append(_wrapped_rows(part, room))
    return parts


def _wrapped_rows(item, room: int):
    """The table with the cells of its widest columns wrapped onto continuation rows until it fits ``room``."""
    widths = _column_widths(item)
    while sum(w + 2 for w in widths) > room:
        widest = max(range(len(widths)), key=widths.__getitem__)
        target = max(MIN_HEADER, room - sum(w + 2 for c, w in enumerate(widths) if c != widest) - 2)
        if target >= widths[widest]:
            break  # the other columns alone fill the page: nothing more to gain
        rows = []
        for row in item.rows:
            if is_span(row):
                rows.append(row)
                continue
            lines = [textwrap.wrap(cell, target, break_long_words=False) or [""] if c == widest else [cell]
                     for c, cell in enumerate(row)]
            for index in range(max(len(cell) for cell in lines)):
                rows.append([cell[index] if index < len(cell) else "" for cell in lines])
        item = replace(item, rows=rows)
        widths = _column_widths(item)
    return item


def table_layout(item) -> tuple[list[list[str]], list[float], float]:
    """Where a table goes: its header wrapped so the table fits the page width, each column's x, the type size.

    A header is wrapped (never cut) only as far as the page needs: the longest header line shrinks until
    the columns fit ``TABLE_CHARS`` or reach the cells' own width. A table still too wide is set in
    smaller type, never below ``MIN_TABLE_SIZE`` (``fit_table`` splits a wider one first), never cut.

    Returns
    -------
    header : list of list of str
        Per column, the lines of its header (every column the same number of lines, blank-padded).
    positions : list of float
        The figure x of each column.
    size : float
        The type size [pt].
    """
    cells = [max((len(row[c]) for row in item.rows if not is_span(row)), default=0) for c in range(len(item.header))]
    limit = max((len(h) for h in item.header), default=1)
    while True:
        wrapped = [textwrap.wrap(h, max(limit, 1), break_long_words=False) or [""] for h in item.header]
        widths = [max(cell, *(len(line) for line in lines)) for cell, lines in zip(cells, wrapped)]
        if sum(w + 2 for w in widths) <= TABLE_CHARS or limit <= MIN_HEADER:
            break
        limit -= 1
    height = max((len(lines) for lines in wrapped), default=1)
    wrapped = [lines + [""] * (height - len(lines)) for lines in wrapped]
    total = sum(w + 2 for w in widths)
    size = max(MIN_TABLE_SIZE, min(TABLE_SIZE, TABLE_SIZE * TABLE_CHARS / total)) if total else TABLE_SIZE
    char = CHAR * size / TABLE_SIZE
    positions, x = [], LEFT + 0.01
    for width in widths:
        positions.append(x)
        x += (width + 2) * char
    return wrapped, positions, size


LIST_GAP = 0.6
"""Lines of space after a bullet list, before the paragraph, note or table that follows it."""


def draw_text_page(title, items, caption="", top=TOP, figure=None):
    """One page figure with the items drawn top-down from ``top``."""
    figure = figure or new_page(title, caption)
    items = [part for item in items for part in fit_table(item)]  # a no-op on the items paginate returned
    y = top
    # a bullet list ends with half a line of space before the text that follows (cold read 8, C9: a paragraph ran on
    # straight after the last bullet); counted here, so a full page sets its lines a little closer instead
    list_ends = [index for index, item in enumerate(items[:-1])
                 if item.kind == "bullet" and items[index + 1].kind not in ("bullet", "heading")]
    # likewise after a note followed by body text (cold read 12, user: the note and the paragraph ran together)
    list_ends += [index for index, item in enumerate(items[:-1])
                  if item.kind == "note" and items[index + 1].kind in ("paragraph", "strong", "bullet")]
    lines = sum(_lines(item) for item in items) + LIST_GAP * len(list_ends)
    line = min(LINE, (top - BOTTOM) / lines) if lines else LINE  # a stretched last page: lines set closer
    for index, item in enumerate(items):
        if item.kind == "heading":
            y -= 0.4 * line
            figure.text(LEFT, y, item.text, fontsize=11, weight="bold", va="top")
            y -= 1.6 * line
        elif item.kind == "table":
            header, positions, size = table_layout(item)
            for level in range(len(header[0])):
                for x, column in zip(positions, header):
                    figure.text(x, y, column[level], fontsize=size, weight="bold", va="top")
                y -= line
            right = positions[-1] + (max(len(text) for text in header[-1]) + 12) * CHAR * size / TABLE_SIZE
            figure.add_artist(_rule(y + 0.25 * line, right))
            for row in item.rows:
                if is_span(row):  # a group heading across the table
                    figure.text(positions[0], y, row[0], fontsize=size, weight="bold", va="top")
                    y -= line
                    continue
                for x, text in zip(positions, row):
                    figure.text(x, y, text, fontsize=size, va="top")
                y -= line
            y -= line
        else:
            indent = 0.02 if item.kind == "bullet" else 0.0
            width = WRAP - (4 if item.kind == "bullet" else 0)
            wrapped = textwrap.wrap(item.text, width) or [""]
            for number, text_line in enumerate(wrapped):
                if item.kind == "bullet" and number == 0:
                    figure.text(LEFT + 0.006, y, "•", fontsize=9.5, va="top")
                figure.text(LEFT + indent, y, text_line, fontsize=9.5 if item.kind != "note" else 8.5, va="top",
                            style="italic" if item.kind == "note" else "normal",
                            weight="bold" if item.kind == "strong" else "normal")
                y -= line
            if item.kind in ("paragraph", "strong"):
                y -= line
            if index in list_ends:
                y -= LIST_GAP * line
    return figure



def _rule(y, right):
    return matplotlib.lines.Line2D([LEFT, min(right, 0.985)], [y, y], color="0.5", lw=0.6)


def items_html(items) -> str:
    """The same items as HTML (headings h3, paragraphs, bullet lists, tables)."""
    parts, in_list = [], False
    for item in items:
        if item.kind == "bullet" and not in_list:
            parts.append("<ul>")
            in_list = True
        elif item.kind != "bullet" and in_list:
            parts.append("</ul>")
            in_list = False
        if item.kind == "heading":
            anchor = f" id='{html.escape(item.anchor, quote=True)}'" if item.anchor else ""
            parts.append(f"<h3{anchor}>{html.escape(item.text)}</h3>")
        elif item.kind == "bullet":
            parts.append(f"<li>{html.escape(item.text)}</li>")
        elif item.kind == "strong":
            parts.append(f"<p class='verdict'><strong>{html.escape(item.text)}</strong></p>")
        elif item.kind == "note":
            parts.append(f"<p class='note'>{html.escape(item.text)}</p>")
        elif item.kind == "table":
            head = "".join(f"<th>{html.escape(h)}</th>" for h in item.header)
            body = "".join(f"<tr><th colspan='{len(row)}'>{html.escape(row[0])}</th></tr>" if is_span(row) else
                           "<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>"
                           for row in item.rows)
            parts.append(f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>")
        else:
            parts.append(f"<p>{html.escape(item.text)}</p>")
    if in_list:
        parts.append("</ul>")
    return "\n".join(parts)
