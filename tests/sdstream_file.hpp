// A test fixture: small-sdstream.tck compressed once per suite at 8 bits
// (the default gives it 16): 14,000+ blocks, enough for several threads'
// runs and several parts of 4096 blocks.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "fiblet/compress.hpp"
#include "test_util.hpp"

namespace fiblet::test {

class SdstreamFile : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        if (!shared_data_available()) return;
        dir_ = std::make_unique<TempDir>();
        path_ = dir_->file("sdstream.fft");
        CompressOptions o;
        o.direction_bits = 8;
        compress_file(shared_data("small-sdstream.tck"), path_, o);
    }
    static void TearDownTestSuite() { dir_.reset(); }
    void SetUp() override {
        if (!shared_data_available()) GTEST_SKIP() << "no shared data";
    }
    static inline std::unique_ptr<TempDir> dir_;
    static inline std::string path_;
};

}  // namespace fiblet::test
