#include "image/BackgroundWriter.h"

#include "common/Clock.h"

namespace snell {

BackgroundWriter::BackgroundWriter(std::unique_ptr<ImageWriter> writer, int width, int maxQueuedRows)
    : writer_(std::move(writer)), width_(width), maxQueuedRows_(std::max(1, maxQueuedRows)) {}

void BackgroundWriter::start() {
    if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
}

BackgroundWriter::~BackgroundWriter() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        abandon_ = true;
    }
    changed_.notify_all();
    if (thread_.joinable()) thread_.join();
}

void BackgroundWriter::writeRows(const float* rgb, int rows) {
    if (!thread_.joinable()) {
        const auto start = Clock::now();
        writer_->writeRows(rgb, rows);
        encodeMs_ += msSince(start);
        blockedMs_ += msSince(start);
        return;
    }
    std::vector<float> band(rgb, rgb + std::size_t(rows) * width_ * 3);
    const auto start = Clock::now();
    std::unique_lock<std::mutex> lock(mutex_);
    // A band larger than the whole queue still goes in once the queue is empty.
    changed_.wait(lock, [&] { return !error_.empty() || queuedRows_ == 0 || queuedRows_ + rows <= maxQueuedRows_; });
    blockedMs_ += msSince(start);
    if (!error_.empty()) throw ImageIOError(error_);
    queue_.push_back(std::move(band));
    queuedRows_ += rows;
    lock.unlock();
    changed_.notify_all();
}

void BackgroundWriter::commit() {
    const auto start = Clock::now();
    {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return !error_.empty() || queuedRows_ == 0; });
        closing_ = true;
    }
    changed_.notify_all();
    if (thread_.joinable()) thread_.join();
    if (!error_.empty()) throw ImageIOError(error_);
    const auto finish = Clock::now();
    writer_->commit();  // the last of the encoding (EXR's offset table, PNG's end)
    encodeMs_ += msSince(finish);
    blockedMs_ += msSince(start);
}

void BackgroundWriter::run() {
    for (;;) {
        std::vector<float> band;
        {
            std::unique_lock<std::mutex> lock(mutex_);
            changed_.wait(lock, [&] { return abandon_ || closing_ || !queue_.empty(); });
            if (abandon_ || queue_.empty()) return;
            band = std::move(queue_.front());
            queue_.pop_front();
        }
        const int rows = int(band.size() / (std::size_t(width_) * 3));
        const auto start = Clock::now();
        std::string error;
        try {
            writer_->writeRows(band.data(), rows);
        } catch (const ImageIOError& e) {
            error = e.what();
        }
        {
            std::lock_guard<std::mutex> lock(mutex_);
            encodeMs_ += msSince(start);
            queuedRows_ -= rows;
            if (!error.empty()) {
                error_ = error;
                abandon_ = true;
            }
        }
        changed_.notify_all();
    }
}

}  // namespace snell
