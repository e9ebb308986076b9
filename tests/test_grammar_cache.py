"""The reference parser kept between processes (:func:`helmcheck.grammar.compile.lark_parser`).

A process that needs the Lark parser loads the one an earlier process built, from the user's
cache directory, instead of building its tables again; the parser loaded reads every line as the
one built does, and a cache file that is partial or not a parser is built again, never an error.
"""

from __future__ import annotations

import subprocess
import sys

from helmcheck.grammar.compile import _LARK_OPTIONS, grammar_text, lark_cache_path

LINES = ["OSD,C,S,P", "OMS,90,2,20,1,10", "OMSTART,0,0,0,0,conformance.mis,", "OMW,Clr", "OPK,41.5,-71.3,1,0.5"]

PROGRAM = """
import sys
from helmcheck.grammar.compile import lark_parser
p = lark_parser()
for body in sys.argv[1:]:
    print(p.parse(body, start="body").pretty().replace("\\n", " | "))
"""


def _parse_in_a_process(cache_home, *bodies) -> list[str]:
    out = subprocess.run([sys.executable, "-c", PROGRAM, *bodies], capture_output=True, text=True, timeout=120,
                         env={"XDG_CACHE_HOME": str(cache_home), "PATH": "/usr/bin:/bin"}, check=True)
    assert out.stderr == "", out.stderr
    return out.stdout.splitlines()


def test_a_parser_loaded_from_the_cache_reads_as_the_one_built(tmp_path):
    from lark import Lark

    built = Lark(grammar_text(), **_LARK_OPTIONS)
    want = [built.parse(b, start="body").pretty().replace("\n", " | ") for b in LINES]
    first = _parse_in_a_process(tmp_path, *LINES)  # builds and keeps it
    path = lark_cache_path(grammar_text()).relative_to(lark_cache_path(grammar_text()).parents[1])
    assert (tmp_path / path).is_file()
    assert first == want
    assert _parse_in_a_process(tmp_path, *LINES) == want  # loaded


def test_a_partial_or_foreign_cache_file_is_built_again(tmp_path):
    path = tmp_path / lark_cache_path(grammar_text()).relative_to(lark_cache_path(grammar_text()).parents[1])
    path.parent.mkdir(parents=True)
    for junk in (b"", b"not a parser\n", b"\x80\x04garbage"):
        path.write_bytes(junk)
        assert _parse_in_a_process(tmp_path, "OSD,C")[0].startswith("body")
        assert path.read_bytes() != junk  # replaced by a whole one
