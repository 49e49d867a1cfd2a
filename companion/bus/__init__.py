"""The vehicle bus: named Queue and Latest channels over iceoryx2 shared memory.

Import from the modules (``companion.bus.node``, ``.channels``, ``.clock``,
``.namespace``): this package imports nothing itself, so that naming a namespace does not
load iceoryx2 and numpy (the command line checks a config's namespace before it hands its
process over to the vehicle).
"""
