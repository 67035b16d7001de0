// file_io.h — reading whole files with the checks every reader of user input needs: regular files
// only, a size limit, and errors that name the file.
#pragma once
#include <string>
#include <vector>

namespace caustica {

// The bytes of `path`. Throws Error("PATH: cannot open: ...") for missing files, directories and
// other non-regular files, and for files of 4 GiB or more.
std::vector<unsigned char> readFileBytes(const std::string& path);
// The same, as a string (text files, hashing).
std::string readFileText(const std::string& path);

}  // namespace caustica
