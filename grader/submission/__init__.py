"""What came in: a submitted file read without following links, validated, its notebook parsed in a bounded
reader, and a Gradescope upload's identity."""
