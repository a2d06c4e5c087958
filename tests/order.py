"""The tests that need the network trained on real motion run after all the others.

``retargeting.load_real`` trains that network once and caches it; a
test that needs it while another process trains it waits on the cache's lock. CI trains it in the
background while the tests run (``.ci/run``), so the tests that need it come last: those marked
``real_network`` and the notebooks in :data:`NOTEBOOKS`. Both parts keep their order, so a
notebook's cells stay together and in order.

The notebooks' cells get the ``real_network`` marker too, so that ``-m real_network`` selects
every test that needs the network and ``-m "not real_network"`` every other (CI runs the others
while the network trains).

To find them: run the suite with ``MOTIONLAB_CACHE`` naming a file instead of a folder (and
``MOTIONLAB_DATA`` set). The tests that need the network then fail; no other does.
"""

from __future__ import annotations

import pytest

NOTEBOOKS = ("03_latent_iteration.ipynb", "07_expanding_a_database.ipynb")
"""The notebooks that retarget real clips with the real-motion network."""


def needs_network(item) -> bool:
    """Whether the collected test ``item`` needs the real-motion network."""
    return item.get_closest_marker("real_network") is not None or item.path.name in NOTEBOOKS


@pytest.hookimpl(tryfirst=True)  # before ``-m`` deselects by marker
def pytest_collection_modifyitems(items) -> None:
    for item in items:
        if item.path.name in NOTEBOOKS:
            item.add_marker(pytest.mark.real_network)
    first = [i for i in items if not needs_network(i)]
    items[:] = first + [i for i in items if needs_network(i)]
