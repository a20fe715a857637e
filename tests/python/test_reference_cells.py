# SPDX-License-Identifier: Apache-2.0
"""The cart-pole preset reproduces the committed reference cells bit for bit (tests/tools/compare_cells.py:
a spread subset of cells of every condition with small caps; the reference records its commit)."""
import pytest

from tests.tools import compare_cells


@pytest.mark.parametrize("condition", compare_cells.load_conditions())
def test_cells_bit_identical_to_reference(condition):
    row = compare_cells.compare([condition])[condition]
    assert row["cells"] == len(compare_cells.CELLS)
    assert row["identical"] == row["cells"], row
