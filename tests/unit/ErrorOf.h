// The message of the volref::Error thrown by `f`, or "" with a test failure when `f` throws nothing or
// another exception: the tests of one-line error messages (scene keys, files, options) read it.
#pragma once
#include <exception>
#include <string>

#include <gtest/gtest.h>

#include "core/Error.h"

namespace volref::test {

template <class F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "not a volref::Error: " << e.what();
        return "";
    }
    ADD_FAILURE() << "no error thrown";
    return "";
}

}  // namespace volref::test
