"""pdverify.pd.bonds.unique_ids: np.unique's answer by a sort (numpy >= 2.3 hashes)."""
import numpy as np
import pytest

from pdverify.pd.bonds import unique_ids


@pytest.mark.parametrize("dtype", [np.int32, np.int64])
@pytest.mark.parametrize("size, high", [(0, 1), (1, 5), (1000, 50), (200_000, 10**9),
                                        (200_000, 1000)])
def test_unique_ids_is_np_unique(size, high, dtype):
    """The same values, order and dtype as np.unique, empty and repeated ids included
    (exact: integers)."""
    ids = np.random.default_rng(size).integers(0, high, size).astype(dtype)
    expected = np.unique(ids)
    got = unique_ids(ids)
    assert got.dtype == expected.dtype
    np.testing.assert_array_equal(got, expected)


def test_unique_ids_flattens_like_np_unique():
    ids = np.array([[3, 1], [3, 2]])
    np.testing.assert_array_equal(unique_ids(ids), np.unique(ids))
