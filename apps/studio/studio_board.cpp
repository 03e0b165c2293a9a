#include "apps/studio/studio_board.h"

namespace dpc::studio {

void StudioBoard::setScene(std::string json) {
  auto text = std::make_shared<const std::string>(std::move(json));
  std::lock_guard<std::mutex> lock(mutex_);
  scene_ = std::move(text);
}

std::shared_ptr<const std::string> StudioBoard::scene() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return scene_;
}

void StudioBoard::publish(std::shared_ptr<const StudioFrame> frame) {
  std::shared_ptr<const StudioFrame> dropped;  // freed outside the lock
  std::lock_guard<std::mutex> lock(mutex_);
  frames_.push_back(std::move(frame));
  if (frames_.size() > kKeptFrames) {
    dropped = std::move(frames_.front());
    frames_.pop_front();
  }
}

std::shared_ptr<const StudioFrame> StudioBoard::latest() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return frames_.empty() ? nullptr : frames_.back();
}

std::shared_ptr<const StudioFrame> StudioBoard::find(uint64_t frame) const {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& f : frames_)
    if (f->frame == frame) return f;
  return nullptr;
}

void StudioBoard::requestListener(const ListenerRequest& r) {
  std::lock_guard<std::mutex> lock(mutex_);
  requests_.listener = r;
}

void StudioBoard::requestSource(size_t index, const glm::vec3& position) {
  std::lock_guard<std::mutex> lock(mutex_);
  requests_.sources.emplace_back(index, position);
}

void StudioBoard::select(size_t source) {
  std::lock_guard<std::mutex> lock(mutex_);
  selected_ = source;
}

StudioRequests StudioBoard::take() {
  std::lock_guard<std::mutex> lock(mutex_);
  return std::exchange(requests_, StudioRequests{});
}

size_t StudioBoard::selected() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return selected_;
}

}  // namespace dpc::studio
