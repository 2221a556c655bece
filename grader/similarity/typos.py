"""Misspellings in comments and strings: two students who misspell the same word the same way is evidence.

Without a dictionary on every machine, the check knows the misspellings English writers make most often
(lists of common misspellings, in our own selection) plus the ones this lab invites; a word counts
when it is one of them.
"""

from __future__ import annotations

import re

MISSPELLINGS = frozenset(
    """
    recieve recieved recieves reciever acheive acheived adress agressive apparantly arguement begining beleive
    beleived calender catagory cheif choosen collegue comming commited completly concious curiousity definately
    definitly dissapoint embarass enviroment enviornment enviroments existance experiance familar finaly foward
    goverment gaurd happend harrass immediatly independant interupt knowlege lenght lenghts libary maintainance
    neccessary necesary noticable occassion occured occurence occuring ommit oppurtunity paralel parrallel
    persistant posession prefered privelege probaly publically realy recomend refered relevent remeber repetion
    rythm seperate seperated seperately sucess succesful succesfully suprise tommorow tounge truely twelth
    untill useable wierd wich whith writting acction actoin enviorment episdoe epsiode episdoes epsiodes
    rewrad reawrd rewads obervation observaton obsevation stategy startegy stratagy threshhold thresold
    veloctiy velcity postion positon accelarate accelerat momentem momemtum iteratons iteraton
    choosen randomely probabilty probabilites avarage averge everage calulate calcualte caluclate
    """.split()
)
_WORD = re.compile(r"[a-z]+")


def misspellings(text: str) -> set[str]:
    """The known misspellings in a comment or string."""
    return {word for word in _WORD.findall(text.lower()) if word in MISSPELLINGS}
