// A directory under /tmp of a test's own, removed with everything in it when
// the object goes (its path is empty where none could be made).
#pragma once

#include <stdlib.h>

#include <filesystem>
#include <string>

namespace snell::testing {

class TemporaryDirectory {
public:
    TemporaryDirectory() {
        char name[] = "/tmp/snell-test-XXXXXX";
        if (::mkdtemp(name)) path_ = name;
    }
    ~TemporaryDirectory() {
        std::error_code ignored;
        if (!path_.empty()) std::filesystem::remove_all(path_, ignored);
    }
    TemporaryDirectory(const TemporaryDirectory&) = delete;
    TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
    const std::string& path() const { return path_; }

private:
    std::string path_;
};

}  // namespace snell::testing
