/*
 * fastdds_peer - a peer of j288-dds on eProsima Fast DDS (Debian's libfastrtps, 2.x), ROS 2's
 * default middleware: the types from fastddsgen over the bridge's IDL as ROS 2 declares them
 * (-DJ288_DDS_AS_ROS2: unbounded), QoS as rmw_fastrtps gives a default ROS 2 publisher and
 * subscription (reliable, volatile, keep last). The participant takes its settings the way a
 * ROS 2 node on Fast DDS does: the default profile of FASTRTPS_DEFAULT_PROFILES_FILE when set
 * (docs/dds.md "When nothing is seen" has the one for a network without multicast).
 *
 * usage: fastdds_peer states [--timeout S]   the next rt/joint_states: 'name POS' lines
 *        fastdds_peer command [--for S] [--hz H] NAME POS
 *                                          rt/joint_command with one joint's position, for S
 *                                          seconds (10) at H per second (50), once matched
 * Domain: $DDS_DOMAIN (0 without). Exit 0 on success, 1 when nothing matched or came within
 * the timeout (default 20 s), 2 on bad usage.
 */
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "sensor_msgsPubSubTypes.h"

using namespace eprosima::fastdds::dds;
using clock_type = std::chrono::steady_clock;
using JointState = sensor_msgs::msg::dds_::JointState_;

namespace {

double seconds_since(clock_type::time_point t0)
{
    return std::chrono::duration<double>(clock_type::now() - t0).count();
}

struct Peer {
    DomainParticipant *pp = nullptr;
    Topic *topic = nullptr;

    explicit Peer(const char *topic_name)
    {
        const char *d = std::getenv("DDS_DOMAIN");
        DomainParticipantFactory *f = DomainParticipantFactory::get_instance();
        (void)f->load_profiles(); /* FASTRTPS_DEFAULT_PROFILES_FILE, as rmw_fastrtps does */
        DomainParticipantQos q;
        (void)f->get_default_participant_qos(q);
        pp = f->create_participant(d != nullptr ? std::atoi(d) : 0, q);
        if (pp == nullptr)
            return;
        TypeSupport ts(new sensor_msgs::msg::dds_::JointState_PubSubType());
        ts.register_type(pp);
        topic = pp->create_topic(topic_name, ts.get_type_name(), TOPIC_QOS_DEFAULT);
    }

    ~Peer()
    {
        if (pp != nullptr) {
            (void)pp->delete_contained_entities();
            (void)DomainParticipantFactory::get_instance()->delete_participant(pp);
        }
    }
};

int states(double timeout_s)
{
    Peer p("rt/joint_states");
    if (p.topic == nullptr)
        return 1;
    Subscriber *sub = p.pp->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
    DataReaderQos rq = DATAREADER_QOS_DEFAULT;
    rq.reliability().kind = RELIABLE_RELIABILITY_QOS;
    rq.history().kind = KEEP_LAST_HISTORY_QOS;
    rq.history().depth = 10;
    DataReader *r = sub->create_datareader(p.topic, rq);
    auto t0 = clock_type::now();
    while (seconds_since(t0) < timeout_s) {
        JointState m;
        SampleInfo si;
        if (r->wait_for_unread_message(Duration_t(0, 100000000)) &&
            r->take_next_sample(&m, &si) == ReturnCode_t::RETCODE_OK && si.valid_data) {
            for (size_t i = 0; i < m.name().size(); i++)
                std::printf("%s %.6f\n", m.name()[i].c_str(),
                            i < m.position().size() ? m.position()[i] : 0.0);
            return 0;
        }
    }
    std::fprintf(stderr, "fastdds_peer: no joint_states in %.0f s\n", timeout_s);
    return 1;
}

int command(double seconds, double hz, const char *name, double pos)
{
    Peer p("rt/joint_command");
    if (p.topic == nullptr)
        return 1;
    Publisher *pub = p.pp->create_publisher(PUBLISHER_QOS_DEFAULT);
    DataWriterQos wq = DATAWRITER_QOS_DEFAULT;
    wq.reliability().kind = RELIABLE_RELIABILITY_QOS;
    wq.history().kind = KEEP_LAST_HISTORY_QOS;
    wq.history().depth = 10;
    DataWriter *w = pub->create_datawriter(p.topic, wq);
    PublicationMatchedStatus st;
    auto t0 = clock_type::now();
    do { /* until the bridge's reader is there */
        (void)w->get_publication_matched_status(st);
        if (st.current_count > 0)
            break;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    } while (seconds_since(t0) < 20.0);
    if (st.current_count == 0) {
        std::fprintf(stderr, "fastdds_peer: no reader matched joint_command\n");
        return 1;
    }
    JointState m;
    m.name().push_back(name);
    m.position().push_back(pos);
    t0 = clock_type::now();
    auto next = t0;
    while (seconds_since(t0) < seconds) {
        (void)w->write(&m);
        next += std::chrono::microseconds(static_cast<long>(1e6 / hz));
        std::this_thread::sleep_until(next);
    }
    return 0;
}

} // namespace

int main(int argc, char **argv)
{
    double timeout_s = 20.0, seconds = 10.0, hz = 50.0;
    int i = 2;
    if (argc < 2)
        return 2;
    std::string cmd = argv[1];
    for (; i + 1 < argc && std::strncmp(argv[i], "--", 2) == 0; i += 2) {
        if (std::strcmp(argv[i], "--timeout") == 0)
            timeout_s = std::atof(argv[i + 1]);
        else if (std::strcmp(argv[i], "--for") == 0)
            seconds = std::atof(argv[i + 1]);
        else if (std::strcmp(argv[i], "--hz") == 0)
            hz = std::atof(argv[i + 1]);
        else
            return 2;
    }
    std::setvbuf(stdout, nullptr, _IOLBF, 0);
    if (cmd == "states" && i == argc)
        return states(timeout_s);
    if (cmd == "command" && argc - i == 2)
        return command(seconds, hz, argv[i], std::atof(argv[i + 1]));
    std::fprintf(stderr, "fastdds_peer: bad usage (see the top of test/dds/fastdds_peer.cpp)\n");
    return 2;
}
