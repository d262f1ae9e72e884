"""Text from the measured repository in Markdown: as code spans, where nothing is markup.

A file name, a function name, an endpoint, a tag or a rule pack's description is written by
whoever wrote the repository. In Markdown, ``<h1>GATES PASSED</h1>.py`` is a heading,
``<img src=x>.py`` an image, ``[click](https:evil.example).py`` a link and ``www.x.com``
an autolink (GitHub's job summaries and comments render all of them). Inside a code span
none of that is read: CommonMark takes its text literally, HTML and entities included. A
span is fenced by one backtick more than the longest run of backticks in the text, so no
backtick in a name can end it early (docs/security.md).
"""

from __future__ import annotations

import re

_BACKTICKS = re.compile(r"`+")
_LAYOUT = {"\n": "\\n", "\r": "\\r", "\t": "\\t", "\u2028": "\\u2028", "\u2029": "\\u2029"}
_LAYOUT_CHARS = re.compile("[\n\r\t\u2028\u2029]")


def code_span(text: object) -> str:
    """``text`` as one Markdown code span (empty text: nothing). Line breaks and tabs are
    shown as ``\\n``, ``\\r``, ``\\t``: a span is one line of a table or a list."""
    shown = _LAYOUT_CHARS.sub(lambda found: _LAYOUT[found.group()], str(text))
    if not shown:
        return ""
    fence = "`" * (max((len(run) for run in _BACKTICKS.findall(shown)), default=0) + 1)
    # CommonMark strips one blank from each end of a span that starts and ends with one,
    # and a backtick at either end would join the fence: pad both ends with a blank then
    pad = " " if shown[0] in "` " or shown[-1] in "` " else ""
    return f"{fence}{pad}{shown}{pad}{fence}"


def table_cell(text: str) -> str:
    """A cell of a Markdown (GitHub) table: a ``|`` escaped (GitHub reads ``\\|`` as a pipe
    inside a code span too), a line break shown as a blank."""
    return text.replace("|", "\\|").replace("\n", " ")
