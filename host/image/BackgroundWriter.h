// An ImageWriter that may encode on a thread of its own: then compressing
// the rows (PNG's deflate, EXR's PIZ) overlaps the render that produces them
// instead of following it. Worth it only where the render leaves a core free
// or the encoding is dear (docs/log/writing-images.md, "Writing images"); until
// start() the rows are written at once, on the caller's thread.
#pragma once

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "image/ImageIO.h"

namespace snell {

class BackgroundWriter {
public:
    // Rows wait in a queue of at most `maxQueuedRows` rows (the producer
    // blocks beyond it, so memory stays bounded).
    BackgroundWriter(std::unique_ptr<ImageWriter> writer, int width, int maxQueuedRows);
    // Encodes on a thread from now on (before the first row).
    void start();
    // Without commit() the file is discarded (ImageWriter's rule).
    ~BackgroundWriter();
    BackgroundWriter(const BackgroundWriter&) = delete;
    BackgroundWriter& operator=(const BackgroundWriter&) = delete;

    // Queues a copy of the rows. Throws the writer's first ImageIOError.
    void writeRows(const float* rgb, int rows);
    // Waits for the queue to drain, then commits. Throws ImageIOError.
    void commit();

    double encodeMs() const { return encodeMs_; }   // the thread's time in the writer
    double blockedMs() const { return blockedMs_; } // the caller's time waiting for it

private:
    void run();

    std::unique_ptr<ImageWriter> writer_;
    int width_;
    int maxQueuedRows_;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<std::vector<float>> queue_;  // bands of rows not yet taken
    int queuedRows_ = 0;                    // rows queued or being written
    bool closing_ = false;                  // all rows given: finish the queue
    bool abandon_ = false;                  // destroyed or failed: stop now
    std::string error_;
    double encodeMs_ = 0.0;
    double blockedMs_ = 0.0;
    std::thread thread_;
};

}  // namespace snell
