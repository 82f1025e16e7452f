# cmake -DROOT=dir -DLIST=files.txt -DOUTPUT=file.cpp -DSYMBOL=name -P HashSources.cmake
# Writes a C++ source defining `const char* const uwscan::bench::SYMBOL`: the SHA-256, in hex,
# of the files LIST names (one absolute path a line), each one's path relative to ROOT and its
# own SHA-256 in the list's order. The same sources hash alike wherever they are checked out.
file(STRINGS ${LIST} files)
set(manifest "")
foreach(path IN LISTS files)
  file(RELATIVE_PATH relative ${ROOT} ${path})
  file(SHA256 ${path} content_hash)
  string(APPEND manifest "${relative} ${content_hash}\n")
endforeach()
string(SHA256 hash "${manifest}")
file(WRITE ${OUTPUT}
  "namespace uwscan::bench {\nextern const char* const ${SYMBOL};\n"
  "const char* const ${SYMBOL} = \"${hash}\";\n}\n")
