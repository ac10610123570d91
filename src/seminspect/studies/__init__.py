"""Studies: experiments that run the library end to end and compare it with the papers.

Each study is one subpackage holding everything it needs: the paper's rows, the runs it makes
or reuses, how it chooses its queries, its records, and the tables and plots it writes.
"""

from seminspect.studies import xflie

__all__ = ["xflie"]
