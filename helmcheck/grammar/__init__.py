"""The wire format of the remote helm protocol: grammar, typed sentences, codec and framer.

``remote_helm.lark`` (in this package) is the one definition of every sentence. This package is
sans-IO: it imports no serial, clock or threading module.

Public API::

    parse(line, profile=DEFAULT) -> Sentence          # raises SentenceError
    decode(line, profile=DEFAULT) -> Decoded           # never raises; .sentence/.error/.findings
    format(sentence) -> bytes                          # canonical: upper-case checksum, CR LF
    checksum(body) -> int;  checksum_hex(body) -> str
    Framer(max_line=256).feed(bytes) -> [Line | Discard]
    prepare()                                          # build lazily-built parsers now (live use)
    read_records(lines) -> [WireEvent];  WireLogWriter(stream)   # the wire log (wirelog.py)

Modules: :mod:`.compile` loads the grammar and derives the parsers; :mod:`.sentences` — the
typed sentence classes; :mod:`.codec` — parse and format; :mod:`.checksum` (RH-FRM-2);
:mod:`.framer` — bytes to lines (RH-FRM-6/7); :mod:`.ranges` — value ranges from the profile;
:mod:`.errors` — errors and findings tagged with their clause; :mod:`.docs` — the generated
grammar reference; :mod:`.wirelog` — the wire-log (capture) format: its directions, records, one
reader and one writer, and the line's 8N1 transmit time.
"""

from .checksum import checksum, checksum_hex
from .codec import KNOWN_IDS, Decoded, decode, format, format_body, parse, prepare
from .errors import Finding, SentenceError
from .framer import Discard, Framer, Line
from .sentences import *  # noqa: F401,F403
from .sentences import __all__ as _sentence_names
from .wirelog import WireEvent, WireLogError, WireLogWriter, read_records

__all__ = [
    "parse", "decode", "format", "format_body", "prepare", "Decoded", "KNOWN_IDS", "checksum",
    "checksum_hex", "Framer", "Line", "Discard", "SentenceError", "Finding", "WireEvent",
    "WireLogError", "WireLogWriter", "read_records", *_sentence_names,
]
