"""Untrusted XML's helpers: an element's attributes as lxml gives them, in linear time."""

from __future__ import annotations

from lxml import etree

from cadkg.ingest.xml_input import attributes_of


def test_attributes_are_those_lxml_gives_in_their_order() -> None:
    # A few attributes, and more than the few read the way lxml reads them.
    many = " ".join(f'{"p:" if i % 3 else ""}m{i}="&lt;{i}"' for i in range(40))
    root = etree.fromstring(
        b'<r xmlns:p="urn:p" xmlns="urn:d" a="1 &amp; 2" p:b="&#233;x" xml:lang="en" c=" s ">'
        b'<p:q z="1"/><e/><f ' + many.encode() + b"/></r>"
    )
    assert len(root[2].attrib) == 40
    for element in root.iter():
        assert list(attributes_of(element).items()) == list(element.attrib.items())
    assert list(attributes_of(root)) == ["a", "{urn:p}b", "{http://www.w3.org/XML/1998/namespace}lang", "c"]
    assert attributes_of(root)["a"] == "1 & 2" and type(attributes_of(root)["c"]) is str


def test_an_element_of_a_hundred_thousand_attributes_takes_no_longer_than_its_parse() -> None:
    import time

    element = etree.fromstring(("<r " + " ".join(f'a{i}="{i}"' for i in range(100_000)) + "/>").encode())
    started = time.process_time()
    found = attributes_of(element)
    # lxml's attrib.items() took about a minute here; walking the attributes once, 0.1 s.
    assert time.process_time() - started < 5
    assert len(found) == 100_000 and found["a99999"] == "99999"
