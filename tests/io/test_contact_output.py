"""The output file of each contact term is named by the term."""
from __future__ import annotations

from types import SimpleNamespace

import pytest
from dolfinx import fem

from dolfinx_mortar import ContactTerm, RigidPlane
from dolfinx_mortar.io.contact_output import output_names
from support.scenes import block_on_plane


def term(name=None, slave_tag=1):
    """What output_names reads of a contact term."""
    return SimpleNamespace(name=name, slave_tag=slave_tag)


def test_output_names_by_name_or_by_slave_tag():
    assert output_names([term()]) == ["slave"]                  # as before: run_slave.xdmf
    assert output_names([term("ground")]) == ["ground"]
    # several unnamed terms: by their slave tags (it was slave, slave1, … by position)
    assert output_names([term(slave_tag=3), term(slave_tag=1)]) == ["slave3", "slave1"]
    assert output_names([term("top"), term(slave_tag=2)]) == ["top", "slave2"]


def test_two_terms_writing_one_file_are_refused():
    with pytest.raises(ValueError, match=r"write <output>_slave1.xdmf: give each "
                                         r"ContactTerm its own name="):
        output_names([term(), term()])
    with pytest.raises(ValueError, match="_a.xdmf"):
        output_names([term("a", 1), term("a", 2)])


def test_a_name_that_cannot_name_a_file_is_refused():
    V, tags = block_on_plane(n=(2, 1))
    u = fem.Function(V)
    plane = RigidPlane([0, 0], [0, 1])
    assert ContactTerm(u, tags, 1, obstacle=plane, penalty=1.0, name="floor-1").name == "floor-1"
    assert ContactTerm(u, tags, 1, obstacle=plane, penalty=1.0).name is None
    with pytest.raises(ValueError, match=r"letters, digits, '_' and '-' only, not 'a/b'"):
        ContactTerm(u, tags, 1, obstacle=plane, penalty=1.0, name="a/b")
    with pytest.raises(TypeError, match="must be a string, not int"):
        ContactTerm(u, tags, 1, obstacle=plane, penalty=1.0, name=3)
