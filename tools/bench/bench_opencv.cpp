// bench_opencv.cpp -- the OpenCV side of `make bench`, on the files tools/bench/bench.c wrote: medianBlur per beam and per sweep, kmeans + convexHull.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

static double now()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

static double median_of(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

int main(int argc, char **argv)
{
    const std::string dir = argc > 1 ? argv[1] : "/tmp";
    const int beams = 400, n = 1200, reps = 41;
    cv::setNumThreads(1); // sonard is single-threaded; OpenCV's thread pool only adds noise on 2 cores
    cv::Mat sweep(beams, n, CV_8U);
    std::ifstream f(dir + "/bench_sweep.bin", std::ios::binary);
    if (!f.read(reinterpret_cast<char *>(sweep.data), beams * n)) {
        std::fprintf(stderr, "bench_opencv: cannot read %s/bench_sweep.bin\n", dir.c_str());
        return 1;
    }
    std::vector<double> t_row, t_2d;
    cv::Mat out(1, n, CV_8U), out2;
    long sink = 0;
    for (int r = 0; r < reps; r++) {
        double t0 = now();
        for (int i = 0; i < beams; i++) {
            cv::medianBlur(sweep.row(i), out, 5); // the same 1 x 1200 rows our 1-D filter gets
            sink += out.at<uint8_t>(0, 7);
        }
        double t1 = now();
        cv::medianBlur(sweep, out2, 5);
        double t2 = now();
        sink += out2.at<uint8_t>(3, 3);
        t_row.push_back((t1 - t0) / (beams * n) * 1e9);
        t_2d.push_back((t2 - t1) / (beams * n) * 1e9);
    }
    struct P {
        int32_t x, y;
        uint32_t w;
    };
    std::vector<P> pts(5000);
    std::ifstream g(dir + "/bench_points.bin", std::ios::binary);
    if (!g.read(reinterpret_cast<char *>(pts.data()), 5000 * sizeof(P))) {
        std::fprintf(stderr, "bench_opencv: cannot read %s/bench_points.bin\n", dir.c_str());
        return 1;
    }
    cv::Mat data(5000, 2, CV_32F);
    for (int i = 0; i < 5000; i++) {
        data.at<float>(i, 0) = (float)pts[i].x;
        data.at<float>(i, 1) = (float)pts[i].y;
    }
    std::vector<double> t_km;
    cv::setRNGSeed(1);
    for (int r = 0; r < reps; r++) {
        cv::Mat labels, centers;
        double t0 = now();
        cv::kmeans(data, 6, labels, cv::TermCriteria(cv::TermCriteria::MAX_ITER | cv::TermCriteria::EPS, 10, 1e-4), 1,
                   cv::KMEANS_PP_CENTERS, centers);
        for (int k = 0; k < 6; k++) {
            std::vector<cv::Point> c, h;
            for (int i = 0; i < 5000; i++)
                if (labels.at<int>(i) == k)
                    c.emplace_back(pts[i].x, pts[i].y);
            if (!c.empty())
                cv::convexHull(c, h);
            sink += (long)h.size();
        }
        t_km.push_back((now() - t0) * 1e3);
    }
    std::printf("cv_median5_row_ns_per_sample %.4f\n", median_of(t_row));
    std::printf("cv_median5x5_ns_per_sample %.4f\n", median_of(t_2d));
    std::printf("cv_kmeans_hull_5000_ms %.4f\n", median_of(t_km));
    std::printf("cv_version %s\n", CV_VERSION);
    std::printf("sink %ld\n", sink & 1);
    return 0;
}
