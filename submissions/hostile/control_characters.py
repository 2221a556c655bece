"""Hostile: terminal escape sequences and bells in what the code prints and in its exception message.

ESC [2J clears a terminal, ESC ] 0 ; ... BEL retitles it, ESC [31m colours what follows; Gradescope shows
them as garbage. Every output of a report (the text summary, Gradescope's results) must show them inert.
"""


def random_blackjack(n):
    """Prints escape sequences, then raises an exception whose message holds more."""
    print("ring\x07 the bell, \x1b[31mred\x1b[0m, \x1b]0;retitled\x07, del\x7f")
    print("a progress line\rrewritten")
    raise ValueError("bad \x1b[2J\x07 value \x1b[31mred\x1b[0m")


def ok():
    """The call the hostile tests make after the sample's."""
    return 42
