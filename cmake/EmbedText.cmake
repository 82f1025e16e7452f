# cmake -DINPUT=file -DOUTPUT=file.cpp -DSYMBOL=name -P EmbedText.cmake
# Writes a C++ source defining `const char* const uwscan::scanner::SYMBOL` with the file's text.
file(READ ${INPUT} text)
set(delimiter "uwscan_embed")
file(WRITE ${OUTPUT}
  "namespace uwscan::scanner {\nextern const char* const ${SYMBOL};\n"
  "const char* const ${SYMBOL} = R\"${delimiter}(${text})${delimiter}\";\n}\n")
