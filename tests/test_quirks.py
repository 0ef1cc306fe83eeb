"""The repair of PyBullet-tolerated XML quirks, against an independent reading of the text.

``used_prefixes`` finds the namespace prefixes a file writes from its colons; the plain
regular expression it replaced (a match tried at every ``<`` and blank) is the oracle here.
"""

import re

from hypothesis import given, settings
from hypothesis import strategies as st

from urdfkit.model.xmlio import tolerate_quirks, used_prefixes

#: The pattern the check used before: a name after ``<`` or a blank, then a colon and a name.
ORACLE = re.compile(rb"[<\s]([A-Za-z_][\w.-]*):[A-Za-z_]")

#: Bytes that make prefixes, break them, or sit near them.
ALPHABET = b"ab_Z09.-:<> \t\n/=\"x\xc3\xa9"


@settings(max_examples=600, deadline=None)
@given(st.lists(st.sampled_from(list(ALPHABET)), max_size=120).map(bytes))
def test_prefixes_match_the_regular_expression(data: bytes) -> None:
    assert used_prefixes(data) == set(ORACLE.findall(data))


def test_long_prefixes_are_found_whole() -> None:
    # Longer than the first window looked at before a colon: the window widens.
    for n in (63, 64, 65, 300, 5000):
        name = b"p" + b"x" * n
        data = b"<robot>\n<" + name + b":camera/>\n" + b" " + name + b"y:a='1'"
        assert used_prefixes(data) == set(ORACLE.findall(data)) == {name, name + b"y"}


def test_undeclared_prefix_is_declared_and_noted() -> None:
    data = b'<robot name="r">\n  <link name="a"/>\n  <sensor:camera/>\n</robot>\n'
    fixed, notes = tolerate_quirks(data)
    assert b'xmlns:sensor="urn:urdfkit:undeclared:sensor"' in fixed
    assert fixed.count(b"\n") == data.count(b"\n")  # no line moves
    assert [line for line, _ in notes] == [3]
    assert "'sensor'" in notes[0][1]
