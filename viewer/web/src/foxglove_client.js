// A minimal read-only Foxglove WebSocket protocol v1 client: serverInfo, advertise, subscribe,
// Message Data (binary opcode 1) with JSON payloads. Enough for plumb's page; Foxglove's own
// client (npm @foxglove/ws-protocol) is what tests/viewer_node uses to check the server.
export const SUBPROTOCOL = 'foxglove.websocket.v1';

export class FoxgloveClient {
  // topics: the topics to subscribe to; onMessage(topic, message, receiveTimeNs)
  constructor(url, topics, { onMessage, onOpen, onClose, onServerInfo }) {
    this.url = url;
    this.topics = new Set(topics);
    this.onMessage = onMessage;
    this.onOpen = onOpen;
    this.onClose = onClose;
    this.onServerInfo = onServerInfo;
    this.topicBySubscription = new Map();
    this.nextSubscription = 1;
    this.decoder = new TextDecoder();
    this.connect();
  }

  connect() {
    const ws = new WebSocket(this.url, [SUBPROTOCOL]);
    ws.binaryType = 'arraybuffer';
    this.ws = ws;
    this.topicBySubscription.clear();
    ws.onopen = () => this.onOpen && this.onOpen();
    ws.onclose = () => {
      this.onClose && this.onClose();
      setTimeout(() => this.connect(), 1000);  // the run may restart; a view keeps trying
    };
    ws.onmessage = (event) => {
      if (typeof event.data === 'string') this.handleText(JSON.parse(event.data));
      else this.handleBinary(new DataView(event.data));
    };
  }

  handleText(message) {
    if (message.op === 'serverInfo' && this.onServerInfo) this.onServerInfo(message);
    if (message.op !== 'advertise') return;
    const subscriptions = [];
    for (const channel of message.channels) {
      if (!this.topics.has(channel.topic) || channel.encoding !== 'json') continue;
      const id = this.nextSubscription++;
      this.topicBySubscription.set(id, channel.topic);
      subscriptions.push({ id, channelId: channel.id });
    }
    if (subscriptions.length > 0) this.ws.send(JSON.stringify({ op: 'subscribe', subscriptions }));
  }

  handleBinary(view) {
    if (view.byteLength < 13 || view.getUint8(0) !== 1) return;  // only Message Data
    const topic = this.topicBySubscription.get(view.getUint32(1, true));
    if (topic === undefined) return;
    const receiveTimeNs = view.getBigUint64(5, true);
    const payload = new Uint8Array(view.buffer, view.byteOffset + 13, view.byteLength - 13);
    this.onMessage(topic, JSON.parse(this.decoder.decode(payload)), receiveTimeNs);
  }
}
