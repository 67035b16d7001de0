// file_io.h — reading whole files with the checks every reader of user input needs: regular files
// only, a size limit, and errors that name the file.
#pragma once
#include <functional>
#include <string>
#include <vector>

namespace caustica {

// The bytes of `path`. Throws Error("PATH: cannot open: ...") for missing files, directories and
// other non-regular files, and for files of 4 GiB or more.
std::vector<unsigned char> readFileBytes(const std::string& path);
// The same, as a string (text files, hashing).
std::string readFileText(const std::string& path);

// Replaces `path` atomically: `write` fills the temporary file `path + tmpSuffix` (its argument),
// which is then flushed to disk and renamed over `path`, and the folder is synced. A crash, kill or
// full disk never leaves a partial file in place of a complete one; on failure the temporary file
// is removed and the error (an Error naming the file) is rethrown.
void writeFileAtomically(const std::string& path, const std::string& tmpSuffix,
                         const std::function<void(const std::string& tmp)>& write);

}  // namespace caustica
