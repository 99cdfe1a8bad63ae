/* test_opencv_ref.cpp -- the core against Debian's OpenCV: medianBlur bit for bit (1-D rows and K x K sweeps), convexHull, kmeans. */
#include <cmath>
#include <cstdlib>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

/* cmocka defines fail(), which collides with std::ios::fail: include it after the C++ headers. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

extern "C" {
#include <cmocka.h>
}

extern "C" {
#include "sonar/hull.h"
#include "sonar/kmeans.h"
#include "sonar/median.h"
}

static uint8_t sonar_like(int i, int j)
{
    /* speckle ((a^2 + b^2) >> 7) with bright blobs and saturated stripes, as in algorithms.md */
    int a = rand() % 64, b = rand() % 64;
    int v = (a * a + b * b) >> 7;
    if ((i / 9) % 7 == 3 && (j / 21) % 5 == 2)
        v += 150;
    if (j < 20)
        v = 230 + rand() % 26;
    return (uint8_t)(v > 255 ? 255 : v);
}

static void test_median_1d_bitexact(void **)
{
    static const int sizes[] = {1, 2, 7, 64, 65, 500, 1200};
    srand(21);
    for (int n : sizes)
        for (int k = 3; k <= SONAR_MAX_MEDIAN; k += 2)
            for (int trial = 0; trial < 20; trial++) {
                cv::Mat row(1, n, CV_8U), ref;
                for (int j = 0; j < n; j++)
                    row.at<uint8_t>(0, j) = trial % 2 ? sonar_like(trial, j) : (uint8_t)rand();
                cv::medianBlur(row, ref, k);
                std::vector<uint8_t> out(n);
                assert_int_equal(sonar_median_1d(row.ptr<uint8_t>(0), out.data(), (uint16_t)n, (uint8_t)k), SONAR_OK);
                for (int j = 0; j < n; j++)
                    if (out[j] != ref.at<uint8_t>(0, j))
                        fail_msg("k=%d n=%d j=%d: ours %d, OpenCV %d", k, n, j, out[j], ref.at<uint8_t>(0, j));
            }
}

static void test_median_2d_bitexact(void **)
{
    static const int shapes[][2] = {{400, 1200}, {67, 500}, {5, 33}, {3, 64}, {2, 10}};
    static sonar_median2d m;
    srand(22);
    for (auto &s : shapes)
        for (int k = 3; k <= SONAR_MAX_MEDIAN2D; k += 2) {
            int rows = s[0], cols = s[1], got = 0;
            cv::Mat sweep(rows, cols, CV_8U), ref;
            for (int i = 0; i < rows; i++)
                for (int j = 0; j < cols; j++)
                    sweep.at<uint8_t>(i, j) = sonar_like(i, j);
            cv::medianBlur(sweep, ref, k);
            assert_int_equal(sonar_median2d_init(&m, (uint8_t)k), SONAR_OK);
            std::vector<uint8_t> out(cols);
            sonar_median_row meta = {0, 0, 0}, om;
            auto check = [&](void) {
                for (int j = 0; j < cols; j++)
                    if (out[j] != ref.at<uint8_t>(got, j))
                        fail_msg("k=%d %dx%d row %d col %d: ours %d, OpenCV %d", k, rows, cols, got, j, out[j],
                                 ref.at<uint8_t>(got, j));
                got++;
            };
            for (int i = 0; i < rows; i++) {
                meta.angle = (uint16_t)i;
                int r = sonar_median2d_push(&m, sweep.ptr<uint8_t>(i), (uint16_t)cols, &meta, out.data(), &om);
                assert_true(r >= 0);
                if (r == 1)
                    check();
            }
            while (sonar_median2d_flush(&m, out.data(), &om) == 1)
                check();
            assert_int_equal(got, rows);
        }
}

static void test_hull_matches_convexhull(void **)
{
    srand(23);
    for (int trial = 0; trial < 300; trial++) {
        int n = 3 + rand() % 800;
        int span = trial % 3 == 0 ? 20 : trial % 3 == 1 ? 5000 : 60000; /* 20 forces many collinear/duplicate points */
        std::vector<cv::Point> cvp(n);
        std::vector<sonar_xy> ours(n), h(2 * n);
        for (int i = 0; i < n; i++) {
            cvp[i] = cv::Point(rand() % (2 * span + 1) - span, rand() % (2 * span + 1) - span);
            ours[i].x = cvp[i].x;
            ours[i].y = cvp[i].y;
        }
        std::vector<cv::Point> ref;
        cv::convexHull(cvp, ref, false, true);
        int k = sonar_hull_build(ours.data(), (uint16_t)n, h.data(), (uint16_t)(2 * n));
        assert_true(k >= 3);
        /* Same polygon: equal doubled areas (exact integers) and every vertex of ours is one of OpenCV's. */
        double ref_area2 = 2.0 * cv::contourArea(ref);
        int64_t a2 = sonar_hull_area2(h.data(), (uint16_t)k);
        if (std::fabs((double)a2 - ref_area2) > 0.5)
            fail_msg("trial %d: area2 ours %lld, OpenCV %.1f", trial, (long long)a2, ref_area2);
        for (int i = 0; i < k; i++) {
            bool found = false;
            for (auto &p : ref)
                found = found || (p.x == h[i].x && p.y == h[i].y);
            if (!found)
                fail_msg("trial %d: our vertex (%d,%d) is not an OpenCV hull vertex", trial, h[i].x, h[i].y);
        }
        assert_true(k <= (int)ref.size());
    }
}

static void test_kmeans_matches_opencv(void **)
{
    srand(24);
    for (int trial = 0; trial < 20; trial++) {
        int k = 2 + trial % 6, n = 5000;
        std::vector<sonar_point> p(n);
        cv::Mat data(n, 2, CV_32F);
        for (int i = 0; i < n; i++) {
            int blob = i % k;
            /* integer millimetres, as the detector uses */
            p[i].x = blob * 4000 + (rand() % 1500) + (rand() % 1500);
            p[i].y = (blob % 3) * 3000 + (rand() % 1500) + (rand() % 1500);
            p[i].w = 1;
            data.at<float>(i, 0) = (float)p[i].x;
            data.at<float>(i, 1) = (float)p[i].y;
        }
        std::vector<sonar_xy> c(k);
        std::vector<uint8_t> lab(n);
        assert_int_equal(sonar_kmeans_seed(p.data(), (uint16_t)n, c.data(), (uint8_t)k), k);
        /* OpenCV from the labels our seeds give: a deterministic reference (attempts = 1) */
        cv::Mat labels(n, 1, CV_32S), centers;
        for (int i = 0; i < n; i++) {
            int best = 0;
            double bd = 1e300;
            for (int j = 0; j < k; j++) {
                double dx = p[i].x - c[j].x, dy = p[i].y - c[j].y, d = dx * dx + dy * dy;
                if (d < bd) {
                    bd = d;
                    best = j;
                }
            }
            labels.at<int>(i) = best;
        }
        double compact = cv::kmeans(data, k, labels, cv::TermCriteria(cv::TermCriteria::MAX_ITER, 50, 0), 1,
                                    cv::KMEANS_USE_INITIAL_LABELS, centers);
        int rounds = sonar_kmeans_lloyd(p.data(), (uint16_t)n, lab.data(), c.data(), (uint8_t)k, 51);
        assert_in_range(rounds, 1, 51);
        int differ = 0;
        for (int i = 0; i < n; i++)
            differ += lab[i] != (uint8_t)labels.at<int>(i);
        if (differ > n / 1000)
            fail_msg("trial %d: %d of %d labels differ", trial, differ, n);
        for (int j = 0; j < k; j++)
            if (std::fabs(c[j].x - centers.at<float>(j, 0)) > 1.0 || std::fabs(c[j].y - centers.at<float>(j, 1)) > 1.0)
                fail_msg("trial %d centre %d: ours (%d,%d), OpenCV (%.1f,%.1f)", trial, j, c[j].x, c[j].y,
                         centers.at<float>(j, 0), centers.at<float>(j, 1));
        double inertia = sonar_kmeans_inertia(p.data(), (uint16_t)n, lab.data(), c.data());
        if (std::fabs(inertia - compact) > 1e-3 * compact)
            fail_msg("trial %d: inertia ours %.0f, OpenCV compactness %.0f", trial, inertia, compact);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_median_1d_bitexact),
        cmocka_unit_test(test_median_2d_bitexact),
        cmocka_unit_test(test_hull_matches_convexhull),
        cmocka_unit_test(test_kmeans_matches_opencv),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
