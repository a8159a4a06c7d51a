"""Access levels, sign-in, CSRF/Origin/Host checks and the acting identity (design.md §9.2).

- ``levels``: protection levels 0..7, the table of functions and their default levels
- ``identity``: who acts in a request; ``service``: users, tokens, sessions, keyswitch
- ``middleware``: security headers, trusted hosts, the access guard (Origin, JSON-only, CSRF rule)
- ``deps``: ``guard``, ``needs(function)``, ``require(request, function)`` for the routers
"""
