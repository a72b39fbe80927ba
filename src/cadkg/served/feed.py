"""The change feed of a served cell, fed by its holder after every change (a reload, an
assignment, loaded files) and at start; a transport only sends on what it hears (HTTP as
Server-Sent Events, ROS on a latched topic).

The comparison of the graph with the one before runs in a thread of its own, so the services
go on answering meanwhile; an edit landing during it is in the next change set.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

from cadkg.changes.feed import ChangeFeed
from cadkg.errors import CadkgError
from cadkg.served.holder import GraphHolder, Served
from cadkg.services.session import Work

__all__ = ["CellFeed"]


class CellFeed:
    """``feed`` publishes each change set; ``revision(served)`` names a graph in it; ``warn``
    hears why a change set could not be made (a graph closed by a reload meanwhile)."""

    def __init__(
        self, holder: GraphHolder, revision: Callable[[Served], str], warn: Callable[[str], None]
    ) -> None:
        self.feed = ChangeFeed()
        self._revision = revision
        self._warn = warn
        self._work = ThreadPoolExecutor(max_workers=1, thread_name_prefix="cadkg-changes")
        holder.on_change = self.changed

    def changed(self, served: Served) -> None:
        """``served`` now holds the served graph as it is after a change (or at start)."""
        served.retain()
        # Now, before the cursors go on over the new graph.
        done = served.passed_work()
        self._work.submit(self._observe, served, done)

    def _observe(self, served: Served, done: dict[str, list[Work]]) -> None:
        try:
            cursors: list[str] = []
            with served.lock:  # where each cursor is now: the new session takes them over
                try:
                    served.session()
                    cursors = list(served.cursor_notes)
                except CadkgError as err:  # its services say so to every caller
                    self._warn(f"change feed: no cursors: {err}")
            # Not under the lock, which would hold the robot's service calls for as long as
            # the queries take.
            self.feed.observe(served.graph, self._revision(served), done, cursors)
        except (CadkgError, OSError, RuntimeError) as err:
            self._warn(f"change feed: {err}")
        finally:
            served.release()

    def shutdown(self) -> None:
        self._work.shutdown(wait=True, cancel_futures=True)
