"""Imported only by the fork server (as its first preload), to tie its life to archmetrics's.

Workers are forked by the fork server and die with it (``PR_SET_PDEATHSIG``, see
:mod:`archmetrics.app.workers`). The fork server would outlive a killed archmetrics,
because multiprocessing hands every worker a copy of the pipe whose closing tells the server
to exit. So the server asks the kernel for the same signal: when archmetrics dies, however
it dies, the server goes, and with it every worker.
"""

from __future__ import annotations

from archmetrics.app.workers import die_with_parent

die_with_parent()
