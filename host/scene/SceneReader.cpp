#include "scene/SceneReader.h"

#include <algorithm>
#include <cstring>
#include <istream>

namespace snell {
namespace {

constexpr std::size_t kChunkBytes = 1 << 16;

const char* find(const char* from, std::size_t n, char c) {
    // memchr's pointer must not be null, even for n = 0.
    return n == 0 ? nullptr : static_cast<const char*>(std::memchr(from, c, n));
}

}  // namespace

SceneReader::SceneReader(std::string_view text, ReadLimits limits)
    : limits_(limits), data_(text.data()), size_(text.size()), atEndOfStream_(true) {
    if (size_ > limits_.maxBytes) {
        size_ = static_cast<std::size_t>(limits_.maxBytes);
        cut_ = true;
    }
}

SceneReader::SceneReader(std::istream& in, ReadLimits limits) : in_(&in), limits_(limits) {}

bool SceneReader::fill() {
    if (atEndOfStream_) return false;
    // The unread bytes (a line begun) move to the front; the buffer grows only
    // while a line is longer than a chunk, so up to maxLineBytes.
    const std::size_t unread = size_ - pos_;
    if (pos_ > 0) std::memmove(storage_.data(), storage_.data() + pos_, unread);
    pos_ = 0;
    size_ = unread;
    if (storage_.size() < unread + kChunkBytes) storage_.resize(unread + kChunkBytes);
    data_ = storage_.data();
    in_->read(storage_.data() + size_, static_cast<std::streamsize>(kChunkBytes));
    auto n = static_cast<std::uint64_t>(in_->gcount());
    if (n == 0) {
        atEndOfStream_ = true;
        failed_ = in_->bad();
        return false;
    }
    if (n > limits_.maxBytes - bytesRead_) {
        // Past the limit: what is left of the input is never read.
        n = limits_.maxBytes - bytesRead_;
        cut_ = atEndOfStream_ = true;
    }
    bytesRead_ += n;
    size_ += static_cast<std::size_t>(n);
    return n > 0;
}

void SceneReader::skipByteOrderMark() {
    static constexpr std::string_view kMark = "\xef\xbb\xbf";
    while (size_ - pos_ < kMark.size() && fill()) {
    }
    if (std::string_view(data_ + pos_, std::min(size_ - pos_, kMark.size())) == kMark) pos_ += kMark.size();
}

bool SceneReader::next(std::string_view& line) {
    if (end_ != ReadEnd::NotYet) return false;
    if (!started_) {
        started_ = true;
        skipByteOrderMark();
    }
    // Each byte is searched once, as it arrives: a NUL stops reading where it
    // is read, an endless line where it passes the limit.
    std::size_t searched = 0;
    for (;;) {
        const char* start = data_ + pos_;
        const std::size_t unread = size_ - pos_;
        const char* lf = find(start + searched, unread - searched, '\n');
        const char* lineEnd = lf ? lf : start + unread;
        const char* nul = find(start + searched, static_cast<std::size_t>(lineEnd - (start + searched)), '\0');
        if (nul && static_cast<std::size_t>(nul - start) < limits_.maxLineBytes) {
            ++line_;
            line = std::string_view(start, static_cast<std::size_t>(nul - start) + 1);
            end_ = ReadEnd::NulByte;
            return true;
        }
        const auto length = static_cast<std::size_t>(lineEnd - start);
        if (length > limits_.maxLineBytes) {
            ++line_;
            end_ = ReadEnd::LineTooLong;
            return false;
        }
        if (lf || (atEndOfStream_ && unread > 0 && !cut_ && !failed_)) {
            ++line_;
            pos_ += length + (lf ? 1 : 0);
            line = std::string_view(start, length);
            // CR LF ends a line; a CR before the end of the input (no LF) is the parser's error.
            if (lf && !line.empty() && line.back() == '\r') line.remove_suffix(1);
            return true;
        }
        if (atEndOfStream_) {
            // A line that the limit or a failed read cut short is not a line.
            end_ = cut_ ? ReadEnd::TooLarge : failed_ ? ReadEnd::ReadFailed : ReadEnd::EndOfInput;
            return false;
        }
        searched = unread;
        fill();
    }
}

namespace {

// Occurrences of each word that start in text[0, limit).
void addOccurrences(std::string_view text, std::size_t limit, const std::vector<std::string_view>& words,
                    std::vector<std::size_t>& counts) {
    for (std::size_t k = 0; k < words.size(); ++k)
        for (std::size_t at = text.find(words[k]); at < limit; at = text.find(words[k], at + 1)) ++counts[k];
}

}  // namespace

std::vector<std::size_t> countOccurrences(std::string_view text, const std::vector<std::string_view>& words) {
    std::vector<std::size_t> counts(words.size(), 0);
    addOccurrences(text, text.size(), words, counts);
    return counts;
}

std::vector<std::size_t> countOccurrences(std::istream& in, const std::vector<std::string_view>& words) {
    std::vector<std::size_t> counts(words.size(), 0);
    std::size_t longest = 1;
    for (std::string_view w : words) longest = std::max(longest, w.size());
    // Each chunk follows the last longest - 1 bytes of the one before, so a
    // word that a chunk's end cuts is found whole, and counted once: where it starts.
    // A NUL byte ends the count, as it ends reading (a binary file).
    std::string buffer;
    std::vector<char> chunk(kChunkBytes);
    for (bool nul = false; !nul;) {
        in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
        auto n = static_cast<std::size_t>(in.gcount());
        if (const char* at = find(chunk.data(), n, '\0')) {
            n = static_cast<std::size_t>(at - chunk.data());
            nul = true;
        }
        buffer.append(chunk.data(), n);
        const std::size_t tail = n == 0 || nul ? 0 : std::min(buffer.size(), longest - 1);
        addOccurrences(buffer, buffer.size() - tail, words, counts);
        if (n == 0) break;
        buffer.erase(0, buffer.size() - tail);
    }
    return counts;
}

}  // namespace snell
