# cmake -DINPUT=file -DOUTPUT=file.cc -DSYMBOL=name -P EmbedFile.cmake
#
# Writes OUTPUT defining `extern const char SYMBOL[]` (the bytes of INPUT, NUL-terminated) and
# `extern const unsigned long SYMBOL_size`. Used to inline Debian's Chart.js into the report (host/run).
file(READ "${INPUT}" hex HEX)
string(LENGTH "${hex}" hex_length)
math(EXPR size "${hex_length} / 2")
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "'\\\\x\\1'," bytes "${hex}")
# Break the initializer into lines of 16 bytes (compilers and editors dislike megabyte lines).
# Each byte is 7 characters ('\xhh',): 16 of them per line.
string(REPEAT "." 112 line)
string(REGEX REPLACE "(${line})" "\\1\n" bytes "${bytes}")
file(WRITE "${OUTPUT}" "// Generated from ${INPUT} by cmake/EmbedFile.cmake: do not edit.\n"
  "extern const char ${SYMBOL}[];\nextern const unsigned long ${SYMBOL}_size;\n"
  "const char ${SYMBOL}[] = {\n${bytes}'\\0'};\nconst unsigned long ${SYMBOL}_size = ${size};\n")
