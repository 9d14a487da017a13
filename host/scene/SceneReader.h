// Scene text read a line at a time in bounded memory, from text in memory or
// from a stream that may never end (a pipe, /dev/zero): at most one chunk and
// one line are held, and reading stops at snell's limits (ParseLimits) and at
// the first NUL byte, which no text file holds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <string_view>
#include <vector>

namespace snell {

struct ReadLimits {
    std::uint64_t maxBytes;    // the whole input
    std::size_t maxLineBytes;  // one line, without its line end
};

// Why reading ended.
enum class ReadEnd {
    NotYet,
    EndOfInput,
    NulByte,      // the last line returned holds it, as its last byte
    LineTooLong,  // at lineNumber(), which was not returned
    TooLarge,     // past maxBytes; a line the limit cut through was not returned
    ReadFailed,
};

class SceneReader {
public:
    SceneReader(std::string_view text, ReadLimits limits);
    SceneReader(std::istream& in, ReadLimits limits);

    // The next line without its LF (or CR LF), into `line`, which stays valid
    // until the next call; false once reading has ended (see end()). A UTF-8
    // byte-order mark at the start of the input is not part of line 1.
    bool next(std::string_view& line);

    ReadEnd end() const { return end_; }
    // The line last returned; after LineTooLong, the line that was too long.
    int lineNumber() const { return line_; }

private:
    bool fill();  // reads one more chunk; false at the end of the stream
    void skipByteOrderMark();

    std::istream* in_ = nullptr;
    ReadLimits limits_;
    std::vector<char> storage_;  // the stream's unread bytes
    const char* data_ = nullptr;
    std::size_t pos_ = 0, size_ = 0;  // the unread bytes are data_[pos_, size_)
    std::uint64_t bytesRead_ = 0;
    bool atEndOfStream_ = false;
    bool cut_ = false;     // input past maxBytes was dropped
    bool failed_ = false;  // the stream reported an error
    bool started_ = false;
    int line_ = 0;
    ReadEnd end_ = ReadEnd::NotYet;
};

// How often each word occurs in a text, or in a stream read to its end in
// chunks (a first pass over a regular file: the sizes to reserve).
std::vector<std::size_t> countOccurrences(std::string_view text, const std::vector<std::string_view>& words);
std::vector<std::size_t> countOccurrences(std::istream& in, const std::vector<std::string_view>& words);

}  // namespace snell
