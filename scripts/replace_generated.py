"""Replaces the generated part of a document (from the line that starts with the marker to
"<!-- end of generated part -->") with a file's text.
Usage: replace_generated.py DOC GENERATED MARKER"""
import sys

doc_path, generated_path, begin = sys.argv[1], sys.argv[2], sys.argv[3]
end = "<!-- end of generated part -->"
doc = open(doc_path).read()
generated = open(generated_path).read().rstrip("\n")
i, j = doc.find(begin), doc.find(end)
if i < 0 or j < 0:
    sys.exit(f"{doc_path}: generated-part markers not found")
open(doc_path, "w").write(doc[:i] + generated + doc[j + len(end):])
