// A client's mistake: an HTTP 4xx status and a message that names the problem (sent as {"error": ...}).
#pragma once

#include <stdexcept>
#include <string>

namespace litgs::serve {

struct RequestError : std::runtime_error {
  RequestError(int status_code, const std::string& message)
      : std::runtime_error(message), status(status_code) {}
  int status;
};

}  // namespace litgs::serve
