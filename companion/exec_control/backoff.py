"""How soon a plug-in that died is started again, alone or composed with others.

A plug-in that dies after running a while is restarted at once; one that keeps dying
waits 0.1, 0.2, 0.4 ... up to 5 s between attempts.
"""

FIRST_BACKOFF_S = 0.0
SECOND_BACKOFF_S = 0.1
MAX_BACKOFF_S = 5.0
STABLE_AFTER_S = 10.0  # a plug-in that ran this long starts its back-off afresh
